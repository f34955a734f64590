"""The adaptive domain through the operators: a bake with Adaptive Domain on writes VDB frames
in the same place as the full domain's (world-aligned: same transform, the smoke's world box
within a cell of the full-domain bake's), and its manifest records the setting.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_adaptive_domain.py
"""

import json
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import (add_domain, add_sphere_source, native, reset_scene, rmtree, run,  # noqa: E402
                     select_only, temp_dir)

RESOLUTION = 32
FRAMES = 8
#: Density above which a voxel counts as smoke for the world box: well above the adaptive
#: threshold (0.005), so that what the box leaves out cannot change the box.
SMOKE = 0.05


def smoke_box(path):
    """(lo, hi) world corners of the voxels holding smoke, and the grid's world_of_voxel_zero and
    voxel size."""
    g = native().read_vdb_grid(path, "density")
    vals = np.asarray(g["values"])
    idx = np.argwhere(vals > SMOKE)
    h = float(g["voxel_size"])
    origin = np.asarray(g["world_of_voxel_zero"], dtype=np.float64)
    lo = origin + (idx.min(axis=0) + np.asarray(g["min"])) * h
    hi = origin + (idx.max(axis=0) + np.asarray(g["min"])) * h
    return lo, hi, origin, h


class AdaptiveDomainBakeTest(unittest.TestCase):
    def setUp(self):
        reset_scene()
        self.tmp = temp_dir("plume_adaptive_")

    def tearDown(self):
        rmtree(self.tmp)

    def bake(self, name, adaptive):
        reset_scene()
        cache = os.path.join(self.tmp, name)
        add_sphere_source(radius=0.2, location=(0.0, 0.0, 0.4))
        dom = add_domain(resolution=RESOLUTION, frame_end=FRAMES, cache_directory=cache + "/")
        dom.plume.domain.adaptive_domain = adaptive
        select_only(dom)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        return os.path.join(cache, "Domain")

    def test_frames_are_world_aligned(self):
        full = self.bake("full", False)
        adaptive = self.bake("adaptive", True)
        with open(os.path.join(adaptive, "manifest.json")) as f:
            solver = json.load(f)["settings"]["solver"]
        self.assertTrue(solver["adaptive_domain"])
        self.assertEqual(solver["adaptive_margin"], 6)
        for frame in range(1, FRAMES + 1):
            name = f"volume_{frame:04d}.vdb"
            lo_f, hi_f, origin_f, h = smoke_box(os.path.join(full, name))
            lo_a, hi_a, origin_a, h_a = smoke_box(os.path.join(adaptive, name))
            self.assertEqual(h, h_a)
            np.testing.assert_array_equal(origin_f, origin_a)
            # Within a cell: the box's open sides change the flow a little, not where it is.
            self.assertLessEqual(float(np.abs(lo_f - lo_a).max()), h + 1e-6, f"frame {frame}")
            self.assertLessEqual(float(np.abs(hi_f - hi_a).max()), h + 1e-6, f"frame {frame}")


if __name__ == "__main__":
    run(AdaptiveDomainBakeTest)
