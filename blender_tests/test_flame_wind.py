"""Structural flames in a wind ([Structural Flames] eq. 1 w, §6.1), through the operators: a
Wind force field along +X makes a candle's flame lean to +X (and it stands upright without one);
a Plume domain baked with Velocity Everywhere (a 20³ domain with a side wind and no smoke at all)
stores its wind in clear air, and as the flames' Wind Domain it bends them; baked without the
setting it stores no velocity there and the flames stand upright.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_flame_wind.py
"""

import math
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import add_domain, native, rmtree, run, select_only, temp_dir  # noqa: E402
from test_flames import flame_scene  # noqa: E402

FRAMES = 12
SETTLED = 6  # frames 6..12: the first spine points have reached the tip
WIND = 0.5   # m/s along +X, about the candle flame's buoyant rise speed
#: Mean tip x − base x (m) that counts as leaning. The candle's attached spine reaches
#: H_i = 5 cm; a side wind as fast as the rise tilts it ~45°, i.e. ~2-3 cm of lean, so 1 cm (a
#: 10° tilt of a 5 cm flame) is well below the lean and well above the still-air spread.
LEAN = 0.01
#: |mean lean| (m) in still air: the Brownian diffusion of eq. 1 is symmetric in x.
UPRIGHT = 0.003


def mean_lean(folder):
    """Mean over frames SETTLED..FRAMES and attached flames of tip x − base x (m)."""
    from plume import flames as flames_mod
    leans = []
    for frame in range(SETTLED, FRAMES + 1):
        sp = flames_mod.read_spines(flames_mod.spines_path(folder, frame))
        ends = np.cumsum(sp["counts"])
        for k, end in enumerate(ends):
            if not sp["separated"][k] and sp["counts"][k] >= 2:
                start = end - sp["counts"][k]
                leans.append(sp["points"][end - 1, 0] - sp["points"][start, 0])
    return float(np.mean(leans))


class FlameWindTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = temp_dir("plume_flame_wind_")

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def candle(self, name):
        folder = os.path.join(self.tmp, name)
        src = flame_scene(folder)
        return src, folder

    def test_force_field(self):
        src, folder = self.candle("field")
        self.assertEqual(bpy.ops.plume.flames_bake(), {'FINISHED'})
        still = mean_lean(folder)
        # A Wind field's Z axis rotated +90° about Y points along +X.
        bpy.ops.object.effector_add(type='WIND', rotation=(0.0, math.pi / 2, 0.0))
        bpy.context.active_object.field.strength = WIND
        select_only(src)
        self.assertEqual(bpy.ops.plume.flames_bake(), {'FINISHED'})
        windy = mean_lean(folder)
        print(f"  force field: mean lean {still * 1000:.2f} mm still, {windy * 1000:.2f} mm "
              f"with a {WIND} m/s Wind field")
        self.assertLess(abs(still), UPRIGHT)
        self.assertGreater(windy, LEAN)

    def bake_domain(self, folder, everywhere):
        """A 20³ domain around the candle, a side wind pulling the air to +X, no smoke source."""
        dom = add_domain(size=0.3, location=(0.0, 0.0, 0.15), resolution=20, frame_start=1,
                         frame_end=FRAMES, cache_directory=folder + "/", name="Wind")
        d = dom.plume.domain
        d.wind, d.wind_strength = (WIND, 0.0, 0.0), 10.0
        d.velocity_everywhere = everywhere
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        dom.hide_render = True
        return dom

    def test_wind_domain(self):
        from plume import cache
        from plume.snapshot import cache_folder_of
        results = {}
        for everywhere in (False, True):
            src, folder = self.candle(f"domain_{everywhere}")
            dom = self.bake_domain(folder, everywhere)
            g = native().read_vdb_grid(cache.volume_path(cache_folder_of(dom), FRAMES), "velocity")
            vel = np.asarray(g["values"], np.float64).reshape(-1, 3)
            density = native().read_vdb_grid(cache.volume_path(cache_folder_of(dom), FRAMES),
                                             "density")
            self.assertEqual(np.asarray(density["values"]).size, 0)  # no smoke anywhere
            scn = bpy.context.scene
            scn.plume_flames.wind_domain = dom
            select_only(src)
            self.assertEqual(bpy.ops.plume.flames_bake(), {'FINISHED'})
            results[everywhere] = (vel, mean_lean(folder))
        masked, still = results[False]
        full, windy = results[True]
        mean_u = full.mean(axis=0) if len(full) else np.zeros(3)
        print(f"  wind domain: velocity voxels {len(masked)} masked, {len(full)} everywhere "
              f"(mean u {mean_u[0]:.3f} m/s); mean lean {still * 1000:.2f} mm -> "
              f"{windy * 1000:.2f} mm")
        self.assertEqual(len(masked), 0)  # the default stores velocity only where there is smoke
        self.assertEqual(len(full), 20 ** 3)  # every cell
        # k_w = 10/s pulls the air to u_wind within 0.1 s; by frame 12 (0.5 s) it is there.
        self.assertGreater(mean_u[0], 0.5 * WIND)
        self.assertLess(abs(still), UPRIGHT)
        self.assertGreater(windy, LEAN)


if __name__ == "__main__":
    run(FlameWindTest)
