"""What Plume tells an artist when the toon, flow-graph or flames operators refuse bad input:
each message names the setting by its label and the panel that shows it ("Depth Threshold (γ)
(Physics Properties › Plume › Toon Smoke) must be >= 0 ... (got -0.1)"), its range and the
value, says what to do in menu words ("add a camera (Add › Camera) ..."), and shows no Python
name, API path or enum identifier. The labels the messages use (ui_words.py) are the
properties' own names, each drawn by the panel the message names.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_messages.py
"""

import contextlib
import io
import os
import re
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

from helpers import (add_domain, add_sphere_source, compat, flame_studio,  # noqa: E402
                     reset_scene, rmtree, run, select_only, temp_dir)
from test_roles_ui import draw_panel  # noqa: E402
from test_tooltips import SNAKE, python_names, python_words  # noqa: E402

TAB = "Physics Properties › Plume"


class MessagesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        reset_scene()
        cls.names = python_names()

    def setUp(self):
        reset_scene()
        self.tmp = temp_dir("plume_messages_")

    def tearDown(self):
        rmtree(self.tmp)

    def refusal(self, operator, *words):
        """operator() refused with an error naming every one of `words` and no Python name;
        the message."""
        with self.assertRaises(RuntimeError) as cm:
            operator()
        msg = str(cm.exception)
        print(f"  {msg.strip()}")
        for w in words:
            self.assertIn(w, msg)
        self.assertEqual(python_words(msg, self.names), [], msg)
        # Nor a name of the core's that no panel shows ("frame_dt"): a snake_case word whose
        # first part is a word, not a paper symbol ("t_max"), outside the folders it names.
        words = SNAKE.findall(re.sub(r"\S*/\S*", "", msg))
        self.assertEqual([w for w in words if len(w.split("_")[0]) > 1], [], msg)
        return msg

    def test_labels_are_the_panels(self):
        """Every label ui_words gives a message is the property's own name, and the panel path
        it names draws that property."""
        from plume import ui_words
        bpy.ops.mesh.primitive_cube_add()
        ob = bpy.context.active_object
        panels = {  # path -> (role, panel class, the property group)
            ui_words.TOON: ('DOMAIN', "PHYSICS_PT_plume_toon", lambda: ob.plume.domain.toon),
            ui_words.FLOWGRAPH: ('DOMAIN', "PHYSICS_PT_plume_flowgraph",
                                 lambda: ob.plume.domain.flowgraph),
            ui_words.FLAMES: ('FLAME_SOURCE', "PHYSICS_PT_plume_flames",
                              lambda: bpy.context.scene.plume_flames),
            ui_words.FLAMES_NOISE: ('FLAME_SOURCE', "PHYSICS_PT_plume_flames_noise",
                                    lambda: bpy.context.scene.plume_flames),
            ui_words.FLAME_SOURCE: ('FLAME_SOURCE', "PHYSICS_PT_plume_flame_source",
                                    lambda: ob.plume.flame),
        }
        checked = 0
        for pipeline, tables in ui_words.PIPELINES.items():
            for path, labels in tables:
                role, panel, group = panels[path]
                bpy.ops.plume.role_set(role=role)
                drawn = set()
                # The Flame Source's settings drawn only when Spread and Colour choose them.
                for spread, colour in (('MAPS', 'IMAGE'), ('MODEL', 'PROFILE')):
                    if role == 'FLAME_SOURCE':
                        ob.plume.flame.spread, ob.plume.flame.color_source = spread, colour
                    drawn |= {name for kind, name in
                              draw_panel(self, getattr(bpy.types, panel), ob) if kind == "prop"}
                rna = group().bl_rna
                for name, label in labels.items():
                    self.assertEqual(rna.properties[name].name, label, f"{pipeline}.{name}")
                    self.assertIn(name, drawn, f"{path} does not draw {pipeline}.{name}")
                    checked += 1
        self.assertGreater(checked, 60)

    def test_toon(self):
        cache = os.path.join(self.tmp, "cache") + "/"
        add_sphere_source()
        dom = add_domain(resolution=12, frame_end=2, cache_directory=cache)
        select_only(dom)
        t = dom.plume.domain.toon
        op = bpy.ops.plume.toon_build
        where = f"({TAB} › Toon Smoke)"
        # Checked before anything else: a setting out of range.
        t.depth_threshold = -0.1
        self.refusal(op, f"{t.bl_rna.properties['depth_threshold'].name} {where} must be >= 0",
                     "(§2.2; got -0.1)")
        t.depth_threshold = 0.15
        t.birth_density = 0.01  # below Death Density (0.05)
        self.refusal(op, f"Death Density (ρ_death) {where} must be >= 0 and below Birth Density "
                         "(ρ_birth) (got 0.05 and 0.01)")
        t.birth_density = 0.5
        t.stencil = 'IMAGE'
        self.refusal(op, "Stencil is Image but Stencil Image", where, "pick an image file")
        t.stencil = 'PUFFY'
        self.refusal(op, "has no bake yet: bake it first (Physics Properties › Plume › Bake)")
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        select_only(dom)
        self.refusal(op, "has no camera", "add a camera (Add › Camera) and make it the scene's "
                     "camera (Scene Properties › Scene › Camera)")
        cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
        bpy.context.scene.collection.objects.link(cam)
        bpy.context.scene.camera = cam
        # The core's own check (ToonParams), its setting named as the panel shows it.
        t.max_size_change = 5.0
        self.refusal(op, f"Max Size Change {where} must be in [0.0001, 1]", "(got 5)")
        t.max_size_change = 0.25
        t.emission_count = 2000000
        self.refusal(op, f"Emission {where} must be in [0, 1e+06] particles per frame (got "
                         "2e+06)")  # the core's number format

    def test_flowgraph(self):
        cache = os.path.join(self.tmp, "cache") + "/"
        dom = add_domain(resolution=12, frame_end=2, cache_directory=cache, name="Fire")
        select_only(dom)
        g = dom.plume.domain.flowgraph
        where = f"({TAB} › Flow-Graph Fire)"
        g.block_size = 0
        self.refusal(bpy.ops.plume.flowgraph_build, f"Block Size (B) {where} must be >= 1",
                     "(got 0)")
        g.block_size = 32
        self.refusal(bpy.ops.plume.flowgraph_build, "at least two baked fire states",
                     f"Record Pathlines ({TAB} › Combustion)")
        self.refusal(bpy.ops.plume.fire_synthesize, "has no flow graph yet",
                     f"Build Flow Graph first ({TAB} › Flow-Graph Fire)")

    def test_flames(self):
        scn = bpy.context.scene
        op = bpy.ops.plume.flames_bake
        f = scn.plume_flames
        self.refusal(op, f"the scene has no Flame Source: select a mesh and press {TAB} › "
                         "Flame Source")
        bpy.ops.mesh.primitive_cylinder_add(radius=0.002, depth=0.01, location=(0, 0, 0.005))
        src = bpy.context.active_object
        src.name = "Candle"
        bpy.ops.plume.role_set(role='FLAME_SOURCE')
        f.cache_directory = os.path.join(self.tmp, "flames") + "/"
        f.frame_start, f.frame_end = 1, 1
        where = f"({TAB} › Flames)"
        keep = f.height_persistent
        f.height_persistent = -1.0
        self.refusal(op, f"Persistent Height (H_p) {where} must be >= 0", "(got -1)")
        f.height_persistent = f.height_intermittent
        self.refusal(op, f"Persistent Height (H_p) {where} must be below Intermittent Height "
                         "(H_i)")
        f.height_persistent = keep
        f.spine_noise_scale = 0.0
        self.refusal(op, f"Spine Noise Scale (Λ) ({TAB} › Flames › Noise) must be in (0, ",
                     "(got 0)")
        f.spine_noise_scale = 0.05
        src.plume.flame.stops = 41.0
        self.refusal(op, f"Flame Source 'Candle': Intensity ({TAB} › Flame Source) must be in "
                         "[-40, 40] stops (got 41)")
        src.plume.flame.stops = 0.0
        src.plume.flame.color_source = 'IMAGE'
        self.refusal(op, f"Flame Source 'Candle' ({TAB} › Flame Source): Colour is Colour Image "
                         "but Colour Image is empty")
        src.plume.flame.color_source = 'PROFILE'
        auto = bpy.ops.plume.flames_auto_exposure
        self.refusal(auto, f"bake them first ({TAB} › Flames › Bake Flames)")
        self.assertEqual(op(), {'FINISHED'})
        self.refusal(auto, "add a camera (Add › Camera) and make it the scene's camera "
                           "(Scene Properties › Scene › Camera)")
        # In EEVEE the film exposure it sets does nothing: a warning says what to set instead,
        # naming the engine as Render Properties › Render Engine shows it.
        flame_studio(scn, (0.0, -0.3, 0.03), 64, 64, 1)
        scn.render.engine = compat.eevee_engine()
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            self.assertEqual(auto(), {'FINISHED'})
        sys.stdout.write(out.getvalue())
        warning = next(line for line in out.getvalue().splitlines() if "Auto Exposure" in line)
        self.assertIn("Warning", warning)
        self.assertIn("Render Properties › Film › Exposure), metered on", warning)
        self.assertRegex(warning, r"Film Exposure is Cycles' only; in (EEVEE|Eevee) set Render "
                                  r"Properties › Color Management › Exposure to [+-]\d")
        self.assertEqual(python_words(warning, self.names), [], warning)


if __name__ == "__main__":
    run(MessagesTest)
