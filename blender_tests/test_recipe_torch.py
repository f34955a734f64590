"""The flames manual's recipe "a torch", performed by its own steps
(`examples/flames/recipe_torch.py`, which the screenshots run too): a new General scene without
its cube, a handle (cylinder r 1.5 cm, 0.5 m long) under a head (UV sphere r 4 cm at z 1 m), the
head made a Flame Source from Preset › Torch, Bake Flames over frames 1-24, the camera at
(0, -1.8, 1.25) m turned (90°, 0, 0) with a 50 mm lens, a black world, Cycles, frame 24, Auto
Exposure, render. The picture the recipe promises: a torch's flames, lit and warm (neither black
nor white), a few tongues some 20-50 cm tall over the head, under the Blender's own view
transform. Only the render's size and samples are set here: 480 x 270, 32 samples.

Run: python3 blender_tests/run.py --blender 5.3 test_recipe_torch.py
"""

import json
import os
import sys
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLES = os.path.join(os.path.dirname(HERE), "examples")
sys.path[:0] = [HERE, EXAMPLES, os.path.join(EXAMPLES, "flames")]

import bpy  # noqa: E402

import fire_look  # noqa: E402
import recipe_kit  # noqa: E402
import recipe_torch  # noqa: E402  (the recipe's steps, shared with its screenshots)
from helpers import image_pixels, lit_extent, render_recipe, rmtree, run, temp_dir  # noqa: E402

#: Measured (frame 24; 3.4.1 Filmic / bpy 5.3 AgX): lit 6.2 / 6.5 % of the frame, hue 38.0° /
#: 27.1°, white 0.0 %; the lit top 0.47 m above the head in both, the lit width 0.17 m (the
#: flames, wider than the 8 cm head); 13 / 15 flames alive (the head's five and the pieces that
#: broke off).
LIT_MIN, LIT_MAX = 0.03, 0.12
HUE_MIN, HUE_MAX = 20.0, 45.0
WHITE_MAX = 0.05
TOP_MIN, TOP_MAX = 0.3, 0.65       # m above the head (z 1.04 m); the Torch preset's H_max: 0.3
WIDTH_MIN, WIDTH_MAX = 0.1, 0.3    # m: wider than the 8 cm head, narrower than a campfire
FLAMES_MIN = 5


class RecipeTorchTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = temp_dir("plume_recipe_torch_")
        t0 = time.perf_counter()
        cls.head = recipe_kit.run(recipe_torch.steps(cls.tmp + "/"))
        scene = bpy.context.scene
        assert scene.render.engine == 'CYCLES'
        t1 = time.perf_counter()
        path, _ = render_recipe("torch")
        cls.seconds = (t1 - t0, time.perf_counter() - t1)
        px = image_pixels(path)
        cls.look = fire_look.measure(px)
        lit = px[..., :3].max(axis=2) > fire_look.LIT
        cls.bottom, cls.top, cls.width = lit_extent(scene, lit)
        with open(os.path.join(cls.tmp, "flames_manifest.json"), encoding="utf-8") as fh:
            cls.flames = json.load(fh)["flames"][-1]
        print(f"  torch recipe: {fire_look.text(cls.look)}; lit from z {cls.bottom:.2f} to "
              f"{cls.top:.2f} m, {cls.width:.2f} m wide; {cls.flames} flames; "
              f"steps {cls.seconds[0]:.1f} s, render {cls.seconds[1]:.1f} s", flush=True)

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def test_the_head_is_a_torch_flame_source(self):
        self.assertEqual(self.head.plume.role, 'FLAME_SOURCE')
        fl = self.head.plume.flame
        self.assertEqual((fl.profile, fl.flames), ('TORCH', 5))
        self.assertAlmostEqual(fl.radius, 0.02)
        self.assertGreaterEqual(self.flames, FLAMES_MIN)

    def test_a_lit_warm_flame(self):
        m = self.look
        self.assertGreater(m["lit_share"], LIT_MIN)
        self.assertLess(m["lit_share"], LIT_MAX)
        self.assertGreater(m["hue"], HUE_MIN)
        self.assertLess(m["hue"], HUE_MAX)
        self.assertLess(m["white_share"], WHITE_MAX)

    def test_a_torch_sized_flame(self):
        head_top = recipe_torch.HEAD["location"][2] + recipe_torch.HEAD["radius"]
        self.assertGreater(self.top - head_top, TOP_MIN)
        self.assertLess(self.top - head_top, TOP_MAX)
        self.assertGreater(self.width, WIDTH_MIN)
        self.assertLess(self.width, WIDTH_MAX)


if __name__ == "__main__":
    run(RecipeTorchTest)
