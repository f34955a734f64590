"""Roles, contract property names, Physics-tab panels and the add-on disable/enable round trip.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_roles_ui.py
"""

import os
import sys
import unittest
from types import SimpleNamespace

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import addon_utils  # noqa: E402
import bpy  # noqa: E402

from helpers import ADDON, enable_addon, reset_scene, run, select_only  # noqa: E402

ROLES = ('NONE', 'DOMAIN', 'SOURCE', 'OBSTACLE', 'FLAME_SOURCE')

DOMAIN_PROPS = (
    # DESIGN.md contract
    "resolution", "frame_start", "frame_end", "cache_directory", "seed", "combustion",
    # every SmokeParams field (resolution/cell_size/origin come from the box, frame_dt from
    # time_scale, boundaries from one enum per side)
    "time_scale", "substeps", "use_cfl", "cfl", "advection", "interpolation", "trace", "gravity",
    "alpha", "beta", "ambient_temperature", "wind", "wind_strength", "vorticity",
    "density_dissipation", "pressure_tolerance", "max_pressure_iterations", "burn_rate",
    "soot_yield", "heat_yield",
    "conductivity", "cooling_rate", "max_temperature", "expansion", "flame_vorticity", "threads",
    "boundary_neg_x", "boundary_pos_x", "boundary_neg_y", "boundary_pos_y", "boundary_neg_z",
    "boundary_pos_z", "volume_object")
SOURCE_PROPS = ("density", "temperature", "fuel", "fuel_noise", "fuel_noise_scale",
                "fuel_noise_rate", "smoke_noise", "smoke_noise_scale",
                "smoke_noise_rate", "velocity", "motion_factor", "point_sources", "candidate_group")

PANELS = ("PHYSICS_PT_plume", "PHYSICS_PT_plume_settings", "PHYSICS_PT_plume_forces",
          "PHYSICS_PT_plume_advection", "PHYSICS_PT_plume_pressure", "PHYSICS_PT_plume_boundaries",
          "PHYSICS_PT_plume_combustion", "PHYSICS_PT_plume_cache", "PHYSICS_PT_plume_source",
          "PHYSICS_PT_plume_flame_smoke", "PHYSICS_PT_plume_obstacle",
          "PHYSICS_PT_plume_flame_source", "PHYSICS_PT_plume_flames",
          "PHYSICS_PT_plume_flames_noise")
FLAME_PANELS = {"PHYSICS_PT_plume_flame_source", "PHYSICS_PT_plume_flames",
                "PHYSICS_PT_plume_flames_noise"}
OPERATORS = ("PLUME_OT_role_set", "PLUME_OT_bake", "PLUME_OT_cache_free", "PLUME_OT_flames_bake",
             "PLUME_OT_flames_free", "PLUME_OT_flames_bake_spines_keyframes",
             "PLUME_OT_flame_preset", "PLUME_OT_flames_auto_exposure")


class FakeLayout:
    """Stands in for UILayout in -b (no window): records calls and checks that every prop() and
    operator() a panel draws exists."""

    def __init__(self, test, log):
        self.test, self.log = test, log

    def _child(self, *args, **kwargs):
        return FakeLayout(self.test, self.log)

    row = column = box = split = grid_flow = column_flow = _child

    def prop(self, data, name, **kwargs):
        self.test.assertIn(name, data.bl_rna.properties.keys(), f"panel draws missing prop {name}")
        self.log.append(("prop", name))

    def operator(self, idname, **kwargs):
        module, op = idname.split(".")
        self.test.assertTrue(hasattr(bpy.types, f"{module.upper()}_OT_{op}"), idname)
        self.log.append(("operator", idname))
        return SimpleNamespace()

    def operator_menu_enum(self, idname, prop, **kwargs):
        module, op = idname.split(".")
        cls = getattr(bpy.types, f"{module.upper()}_OT_{op}", None)
        self.test.assertIsNotNone(cls, idname)
        rna = getattr(getattr(bpy.ops, module), op).get_rna_type()
        self.test.assertEqual(rna.properties[prop].type, 'ENUM', f"{idname}.{prop}")
        self.log.append(("operator_menu_enum", idname))

    def label(self, **kwargs):
        self.log.append(("label", kwargs.get("text", "")))

    def separator(self, **kwargs):
        pass


def draw_panel(test, cls, ob):
    """poll() and, if it passes, draw_header()/draw() of a panel class for object `ob`."""
    context = SimpleNamespace(object=ob, active_object=ob, scene=bpy.context.scene)
    if hasattr(cls, "poll") and not cls.poll(context):
        return None
    log = []
    panel = SimpleNamespace(layout=FakeLayout(test, log))
    if hasattr(cls, "draw_header"):
        cls.draw_header(panel, context)
    cls.draw(panel, context)
    return log


class RolesUiTest(unittest.TestCase):
    def setUp(self):
        reset_scene()
        bpy.ops.mesh.primitive_cube_add(size=2.0)
        self.cube = bpy.context.active_object

    def test_role_set_each_role(self):
        for role in ROLES + ('DOMAIN',):
            self.assertEqual(bpy.ops.plume.role_set(role=role), {'FINISHED'})
            self.assertEqual(self.cube.plume.role, role)

    def test_role_set_applies_to_selected_meshes(self):
        bpy.ops.mesh.primitive_uv_sphere_add(location=(3, 0, 0))
        sphere = bpy.context.active_object
        self.cube.select_set(True)
        bpy.ops.plume.role_set(role='SOURCE')
        self.assertEqual((sphere.plume.role, self.cube.plume.role), ('SOURCE', 'SOURCE'))
        bpy.ops.plume.role_set(role='DOMAIN')  # a domain is only ever the active object
        self.assertEqual((sphere.plume.role, self.cube.plume.role), ('DOMAIN', 'SOURCE'))

    def test_role_set_without_active_object_reports(self):
        select_only(None)
        with self.assertRaises(RuntimeError):
            bpy.ops.plume.role_set(role='DOMAIN')

    def test_contract_property_names(self):
        p = self.cube.plume
        self.assertEqual(set(p.bl_rna.properties["role"].enum_items.keys()), set(ROLES))
        for name in DOMAIN_PROPS:
            self.assertIn(name, p.domain.bl_rna.properties.keys())
        for name in SOURCE_PROPS:
            self.assertIn(name, p.source.bl_rna.properties.keys())
        self.assertIn("slip", p.obstacle.bl_rna.properties.keys())
        self.assertEqual(set(p.obstacle.bl_rna.properties["slip"].enum_items.keys()),
                         {'NO_SLIP', 'FREE_SLIP'})
        self.assertEqual(p.domain.cache_directory, "//plume_cache/")
        self.assertEqual(p.domain.bl_rna.properties["cache_directory"].subtype, 'DIR_PATH')
        self.assertEqual((p.source.point_sources, p.source.candidate_group), (16, -1))
        self.assertEqual(p.domain.boundary_neg_z, 'CLOSED')
        self.assertEqual(p.domain.boundary_pos_z, 'OPEN')
        self.assertEqual(len(p.source.velocity), 3)
        self.assertIn("ε", p.domain.bl_rna.properties["vorticity"].description)
        self.assertIn("Fedkiw", p.domain.bl_rna.properties["vorticity"].description)

    def test_no_hard_limits(self):
        d = self.cube.plume.domain
        for value in (0, 5000, -3):
            d.resolution = value
            self.assertEqual(d.resolution, value)
        d.vorticity = -1.0
        self.assertEqual(d.vorticity, -1.0)
        d.alpha = float("nan")
        self.assertNotEqual(d.alpha, d.alpha)

    def test_panels_registered(self):
        for name in PANELS:
            cls = getattr(bpy.types, name, None)
            self.assertIsNotNone(cls, name)
            self.assertEqual(cls.bl_context, "physics")
            self.assertEqual(cls.bl_space_type, 'PROPERTIES')
        for name in OPERATORS:
            self.assertTrue(hasattr(bpy.types, name), name)
        self.assertEqual(bpy.types.PLUME_OT_bake.bl_options, {'REGISTER'})
        self.assertEqual(bpy.types.PLUME_OT_cache_free.bl_options, {'REGISTER'})

    def test_panels_draw_for_each_role(self):
        expected = {
            'NONE': {"PHYSICS_PT_plume"},
            'DOMAIN': set(PANELS) - {"PHYSICS_PT_plume_source", "PHYSICS_PT_plume_obstacle"}
            - FLAME_PANELS,
            'SOURCE': {"PHYSICS_PT_plume", "PHYSICS_PT_plume_source"},
            'FLAME_SOURCE': {"PHYSICS_PT_plume"} | FLAME_PANELS,
            'OBSTACLE': {"PHYSICS_PT_plume", "PHYSICS_PT_plume_obstacle"},
        }
        for role in ROLES:
            bpy.ops.plume.role_set(role=role)
            drawn = {}
            for name in PANELS:
                log = draw_panel(self, getattr(bpy.types, name), self.cube)
                if log is not None:
                    drawn[name] = log
            self.assertEqual(set(drawn), expected[role], role)
            roles_drawn = [e for e in drawn["PHYSICS_PT_plume"] if e == ("operator", "plume.role_set")]
            self.assertEqual(len(roles_drawn), len(ROLES))
        cache_log = draw_panel(self, bpy.types.PHYSICS_PT_plume_cache, self.cube) or []
        self.assertNotIn(("operator", "plume.bake"), cache_log)  # role is OBSTACLE by now
        bpy.ops.plume.role_set(role='DOMAIN')
        cache_log = draw_panel(self, bpy.types.PHYSICS_PT_plume_cache, self.cube)
        self.assertIn(("operator", "plume.bake"), cache_log)
        self.assertIn(("operator", "plume.cache_free"), cache_log)
        self.assertTrue(any(e[0] == "label" and e[1].startswith("Frames: 0 / 50") for e in cache_log))

    def test_messages_name_the_panel_that_draws_the_setting(self):
        """A bake's message names a domain setting by its label and the panel that draws it
        (setting_paths.py): every setting of that table is drawn by the panel it names."""
        from plume import ui
        from plume import setting_paths
        panels = {cls.bl_label: cls for cls in ui.classes
                  if getattr(cls, "bl_parent_id", "") == "PHYSICS_PT_plume"}
        for role, table in (('DOMAIN', setting_paths.DOMAIN_PANELS),
                            ('SOURCE', setting_paths.SOURCE_PANELS)):
            bpy.ops.plume.role_set(role=role)
            for label, names in table:
                log = draw_panel(self, panels[label], self.cube)
                drawn = {name for kind, name in log if kind == "prop"}
                self.assertLessEqual(set(names), drawn, label)
        self.assertEqual(
            setting_paths.in_ui_words("Plume: domain 'Cube': turbulence_scale must be in [0, 9]; "
                                      "turbulence_rate too (got -1)"),
            "Plume: domain 'Cube': Turbulence Size (Physics Properties › Plume › Forces) must be "
            "in [0, 9]; Turbulence Speed too (got -1)")
        self.assertEqual(
            setting_paths.in_ui_words("Plume: source 'S': candidate_split 2 needs 4 point "
                                      "sources: lower candidate_split"),
            "Plume: source 'S': Split Into Groups (Physics Properties › Plume › Source) 2 needs "
            "4 point sources: lower Split Into Groups")
        unknown = "Plume: domain 'Cube': 3 streaklines over 5 frames"
        self.assertEqual(setting_paths.in_ui_words(unknown), unknown)

    def test_panel_hidden_without_object(self):
        context = SimpleNamespace(object=None, active_object=None)
        self.assertFalse(bpy.types.PHYSICS_PT_plume.poll(context))
        self.assertFalse(bpy.types.PHYSICS_PT_plume_settings.poll(context))

    def test_disable_enable_round_trip(self):
        bpy.ops.plume.role_set(role='DOMAIN')
        self.cube.plume.domain.resolution = 77
        addon_utils.disable(ADDON, default_set=True)
        self.assertFalse(addon_utils.check(ADDON)[1])
        for name in PANELS + OPERATORS:
            self.assertFalse(hasattr(bpy.types, name), f"{name} still registered")
        self.assertFalse(hasattr(bpy.types.Object, "plume"))
        enable_addon()
        self.assertTrue(addon_utils.check(ADDON)[1])
        for name in PANELS + OPERATORS:
            self.assertTrue(hasattr(bpy.types, name), f"{name} not registered again")
        # Values stored in the file survive the round trip.
        self.assertEqual(self.cube.plume.role, 'DOMAIN')
        self.assertEqual(self.cube.plume.domain.resolution, 77)
        self.assertEqual(bpy.ops.plume.role_set(role='SOURCE'), {'FINISHED'})


if __name__ == "__main__":
    run(RolesUiTest)
