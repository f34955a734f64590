"""Lit smoke sheets: with Shading set to Lit, the streak sheets take their light from the
scene's lamps (a thin translucent film), while the paper's Emission model glows the same
whatever the lights. On the Figure 1 setup of test_streak_surfaces.py (50³, 20 point sources,
40 frames), built once per shading; frame 40 rendered (Cycles CPU, 120 x 160, 16 samples, a
black world and no backdrop) with a sun of strength 0 and 4:
- Lit: the sheets are black without the sun and clearly lit with it;
- Emission: the sun changes nothing (emission is not lit, and a black world lights nothing).

Run: python3 blender_tests/run.py --blender all blender_tests/test_sheet_lit.py
"""

import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import (OUT_DIR, image_pixels, reset_scene, rmtree, run, select_only,  # noqa: E402
                     temp_dir)
from test_streak_surfaces import FRAMES, build_scene, surface_objects  # noqa: E402

#: Mean display value of the sheets' pixels (those the sheets cover in the Emission render).
#: Measured: Lit 0.000-0.002 without the sun, 0.184-0.219 with it (3.4.1 0.219, 4.2-5.3
#: 0.184-0.189); Emission 0.395-0.426 with and without (equal to the last digit).
LIT_DARK_MAX = 0.02
LIT_SUN_MIN = 0.1
EMISSION_SUN_EFFECT_MAX = 0.01


def studio(path, sun_strength):
    scn = bpy.context.scene
    scn.render.engine = 'CYCLES'
    scn.cycles.device = 'CPU'
    scn.cycles.samples = 16
    scn.cycles.use_denoising = False
    scn.render.resolution_x, scn.render.resolution_y = 120, 160
    scn.render.resolution_percentage = 100
    scn.render.image_settings.file_format = 'PNG'
    scn.render.filepath = path
    smoke = bpy.data.objects.get("Domain_smoke")
    if smoke is not None:
        smoke.hide_render = True
    if scn.world is None:
        scn.world = bpy.data.worlds.new("World")
    scn.world.use_nodes = True
    scn.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    if scn.camera is None:
        cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
        scn.collection.objects.link(cam)
        cam.location = (0.0, -2.6, 1.0)
        cam.rotation_euler = (np.pi / 2, 0.0, 0.0)
        scn.camera = cam
        sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", 'SUN'))
        sun.rotation_euler = (0.9, 0.0, 0.6)  # from the camera's side, above
        scn.collection.objects.link(sun)
    bpy.data.objects["Sun"].data.energy = sun_strength
    bpy.ops.render.render(write_still=True)
    return image_pixels(path)[..., :3].max(axis=2)


class SheetLitTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        reset_scene()
        cls.tmp = temp_dir("plume_sheet_lit_")
        cls.out = os.path.join(OUT_DIR, "sheet_lit")
        os.makedirs(cls.out, exist_ok=True)
        cls.dom = build_scene(os.path.join(cls.tmp, "cache"))
        assert bpy.ops.plume.bake() == {'FINISHED'}
        cls.values = {}
        for shading in ('EMISSION', 'LIT'):
            select_only(cls.dom)
            cls.dom.plume.domain.sheet_shading = shading
            assert bpy.ops.plume.surfaces_build() == {'FINISHED'}
            assert surface_objects()
            bpy.context.scene.frame_set(FRAMES)
            for sun in (0.0, 4.0):
                path = os.path.join(cls.out, f"{shading.lower()}_sun{sun:g}.png")
                cls.values[shading, sun] = studio(path, sun)
        cls.sheet = cls.values['EMISSION', 0.0] > 0.05  # the pixels the sheets cover
        for key, v in sorted(cls.values.items()):
            print(f"  {key[0]} sun {key[1]:g}: mean of the sheets' pixels "
                  f"{v[cls.sheet].mean():.3f}")

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def mean(self, shading, sun):
        return float(self.values[shading, sun][self.sheet].mean())

    def test_sheets_cover_pixels(self):
        self.assertGreater(int(self.sheet.sum()), 200)

    def test_lit_sheets_take_the_lamps_light(self):
        self.assertLess(self.mean('LIT', 0.0), LIT_DARK_MAX)
        self.assertGreater(self.mean('LIT', 4.0), LIT_SUN_MIN)

    def test_emission_sheets_ignore_the_lamps(self):
        self.assertLess(abs(self.mean('EMISSION', 4.0) - self.mean('EMISSION', 0.0)),
                        EMISSION_SUN_EFFECT_MAX)

    def test_material_has_the_lit_film(self):
        mats = [s.material for o in surface_objects() for s in o.material_slots if s.material]
        self.assertTrue(mats)
        for mat in mats:
            self.assertTrue(any(n.label == "Lit Film" for n in mat.node_tree.nodes), mat.name)


if __name__ == "__main__":
    run(SheetLitTest)
