"""Streak surfaces at an artist's scale ([Smoke Surfaces] §3.2): the scene a new user makes - a
2 m domain at 40³, a UV sphere of radius 0.25 m as the Source, Streak Surfaces on, every other
setting at its default - traces a few dozen streaklines (a rim of point sources, point_rim.py;
with Placement Cells, Max Streaklines thins the 16 point sources per source cell); the Streak
Surfaces panel shows that number before baking, and it is what the bake traces; placement and
thinning are seeded; a count whose particles would not fit in memory is refused before anything
is written.

Run: blender_tests/run.py --blender {3.4,4.5,5.0} test_streak_defaults.py
"""

import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import (add_domain, add_sphere_source, assert_reports_error, native,  # noqa: E402
                     reset_scene, rmtree, run, select_only, temp_dir, tree_listing)

FRAMES = 3


def artist_scene(cache_dir, frame_end=FRAMES):
    """The newcomer's sphere scene: defaults everywhere but Streak Surfaces on."""
    add_sphere_source(radius=0.25, location=(0.0, 0.0, 0.35))
    dom = add_domain(resolution=40, frame_end=frame_end, cache_directory=cache_dir + "/")
    dom.plume.domain.streaks = True
    select_only(dom)
    return dom


def traced(cache_dir, frame=1, domain="Domain"):
    return native().read_streak_file(os.path.join(cache_dir, domain, f"streaks_{frame:04d}.bin"))


class StreakDefaultsTest(unittest.TestCase):
    def setUp(self):
        reset_scene()
        self.tmp = temp_dir("plume_streak_defaults_")
        from plume import streak_count
        self.count = lambda dom: streak_count.count(native(), bpy.context.scene, dom)

    def tearDown(self):
        rmtree(self.tmp)

    def assert_bake_traces(self, dom, kept):
        """The bake traces `kept` streaklines, and a second bake from scratch places the same
        point sources (seeded)."""
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        first = traced(self.tmp)
        self.assertEqual(len(first["counts"]), kept)
        bpy.ops.plume.cache_free()
        select_only(dom)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        np.testing.assert_array_equal(traced(self.tmp)["positions"], first["positions"])

    def test_default_scene_traces_what_the_panel_says(self):
        """Every default: a rim of point sources (point_rim.py), one per cell of its length:
        a few dozen streaklines, the count the panel shows before the bake."""
        dom = artist_scene(self.tmp)
        d = dom.plume.domain
        self.assertEqual(d.max_streaklines, 256)
        self.assertEqual(bpy.data.objects["Source"].plume.source.point_placement, 'RIM')
        kept, placed = self.count(dom)
        print(f"  panel: {kept} streaklines of {placed} point sources")
        # A ring 4/5 of the way out on a 0.25 m sphere at 20 cells/m: 2π 0.2 m = 25 cells long.
        self.assertEqual(kept, placed)
        self.assertTrue(20 <= kept <= 32, kept)
        from plume import streak_count
        self.assertEqual(streak_count.label(native(), bpy.context.scene, dom),
                         f"{kept:,} streaklines")
        self.assert_bake_traces(dom, kept)
        # A cap below the rim's count places the rim again with fewer points.
        d.max_streaklines = 12
        self.assertEqual(self.count(dom), (12, placed))

    def test_cells_placement_thinned_to_the_cap(self):
        """Placement Cells (the paper's 16 random points per source cell) on the same sphere:
        thousands of point sources, thinned at random to Max Streaklines; what the panel says."""
        dom = artist_scene(self.tmp)
        d = dom.plume.domain
        bpy.data.objects["Source"].plume.source.point_placement = 'CELLS'
        self.assertEqual(bpy.data.objects["Source"].plume.source.point_sources, 16)
        kept, placed = self.count(dom)
        print(f"  panel: {kept} streaklines of {placed} point sources")
        # 16 per cell of a 0.25 m sphere at 20 cells/m: hundreds of cells, thousands of points.
        self.assertGreater(placed, 2000)
        self.assertEqual(kept, 256)
        from plume import streak_count
        self.assertIn("256 streaklines (of", streak_count.label(native(), bpy.context.scene, dom))
        self.assert_bake_traces(dom, kept)
        # 0 keeps every point source; the panel follows the setting at once.
        d.max_streaklines = 0
        self.assertEqual(self.count(dom), (placed, placed))

    def test_thinning_keeps_each_source_in_proportion(self):
        dom = artist_scene(self.tmp)
        bpy.data.objects["Source"].plume.source.point_placement = 'CELLS'
        small = add_sphere_source(radius=0.12, location=(0.5, 0.0, 0.35), name="Small")
        small.plume.source.point_placement = 'CELLS'
        small.plume.source.point_sources = 4
        select_only(dom)
        dom.plume.domain.max_streaklines = 100
        kept, placed = self.count(dom)
        self.assertLessEqual(kept, 100 + 2)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        snap = traced(self.tmp)
        groups = np.asarray(snap["groups"])
        self.assertEqual(len(groups), kept)
        per_group = np.bincount(groups - groups.min())
        print(f"  streaklines per source: {per_group.tolist()} of {kept} ({placed} placed)")
        self.assertEqual(len(per_group), 2)  # both Sources keep streaklines
        self.assertTrue(all(n >= 2 for n in per_group))

    def test_too_many_streaklines_for_memory_refused(self):
        dom = artist_scene(self.tmp, frame_end=5000)
        d = dom.plume.domain
        d.max_streaklines = 0
        bpy.data.objects["Source"].plume.source.point_placement = 'CELLS'
        bpy.data.objects["Source"].plume.source.point_sources = 10000
        select_only(dom)
        folder = os.path.join(self.tmp, "Domain")
        assert_reports_error(
            self, bpy.ops.plume.bake, r"streaklines over 5000 frames hold [0-9.]+ GB of "
            r"particles, more than the [0-9.]+ GB of memory free: lower Max Streaklines",
            lambda: (tree_listing(folder), len(bpy.data.objects), len(bpy.data.volumes)))
        self.assertFalse(os.path.exists(folder))

    def test_bad_max_streaklines_refused(self):
        dom = artist_scene(self.tmp)
        dom.plume.domain.max_streaklines = 1
        folder = os.path.join(self.tmp, "Domain")
        assert_reports_error(self, bpy.ops.plume.bake,
                             r"Max Streaklines \(Physics Properties › Plume › Streak "
                             r"Surfaces\) must be 0 \(no limit\) or in \[2, ",
                             lambda: tree_listing(folder))


if __name__ == "__main__":
    run(StreakDefaultsTest)
