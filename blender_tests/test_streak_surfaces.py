"""Streak surfaces end to end ([Smoke Surfaces] §3.2-3.4, the paper's Figure 1 setup): a 50³
domain with one tiny source cell holding 20 point sources bakes with streaks on, then
plume.surfaces_build makes >= 2 SURFACE objects whose points follow the cache on frame changes,
and a Cycles render shows semi-transparent sheets. Bad input gives a clear error, changes nothing.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_streak_surfaces.py
PNG renders go to $PLUME_TEST_OUT (default /tmp/plume_test_out).
"""

import os
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import (OUT_DIR, add_domain, assert_reports_error, image_pixels,  # noqa: E402
                     reset_scene, rmtree, run, select_only, temp_dir)

RESOLUTION = 50
FRAMES = 40
POINT_SOURCES = 20


def build_scene(cache_dir, frame_end=FRAMES, point_sources=POINT_SOURCES, streaks=True):
    """Figure 1: a single small source cell low in a 50³ domain, smoke rising from it."""
    cell = 2.0 / RESOLUTION
    # Cell centre near the bottom middle of the domain [-1, 1]² x [0, 2].
    centre = (0.5 * cell, 0.5 * cell, 0.2 + 0.5 * cell)
    bpy.ops.mesh.primitive_cube_add(size=cell * 0.9, location=centre)
    src = bpy.context.active_object
    src.name = "Incense"
    bpy.ops.plume.role_set(role='SOURCE')
    s = src.plume.source
    s.point_placement = 'CELLS'
    s.point_sources = point_sources
    s.velocity = (0.0, 0.0, 1.0)
    s.density = 1.0
    s.temperature = 2.0
    src.hide_render = True
    dom = add_domain(resolution=RESOLUTION, frame_end=frame_end, cache_directory=cache_dir + "/")
    d = dom.plume.domain
    d.streaks = streaks
    d.vorticity = 0.3
    # The paper's solver: the swirl comes from vorticity confinement alone, from an even source
    # (no Turbulence, no Breakup: the defaults for a newcomer's scene, test_streak_lively.py).
    d.turbulence = 0.0
    s.smoke_noise = 0.0
    select_only(dom)
    return dom


def surface_objects():
    return [o for o in bpy.data.objects if o.type == 'SURFACE']


def counts():
    return (len(bpy.data.objects), len(bpy.data.curves), len(bpy.data.materials),
            len(bpy.data.images), len(bpy.data.collections))


def setup_render(path, samples=16):
    scn = bpy.context.scene
    scn.render.engine = 'CYCLES'
    scn.cycles.device = 'CPU'
    scn.cycles.samples = samples
    scn.cycles.use_denoising = False
    scn.render.resolution_x, scn.render.resolution_y = 160, 120
    scn.render.resolution_percentage = 100
    scn.render.film_transparent = False
    scn.render.image_settings.file_format = 'PNG'
    scn.render.image_settings.color_mode = 'RGBA'
    scn.render.filepath = path
    smoke = bpy.data.objects.get("Domain_smoke")
    if smoke is not None:
        smoke.hide_render = True  # only the sheets differ between the two renders
    if scn.world is None:
        scn.world = bpy.data.worlds.new("World")
    scn.world.use_nodes = True
    bg = scn.world.node_tree.nodes.get("Background")
    bg.inputs["Color"].default_value = (0.02, 0.02, 0.03, 1.0)
    if scn.camera is None:
        cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
        scn.collection.objects.link(cam)
        cam.location = (0.0, -2.2, 1.1)
        cam.rotation_euler = (np.pi / 2, 0.0, 0.0)
        scn.camera = cam
        light = bpy.data.objects.new("Light", bpy.data.lights.new("Light", 'SUN'))
        scn.collection.objects.link(light)
        # A backdrop plane with a checker pattern: seen through the sheets where they are thin.
        bpy.ops.mesh.primitive_plane_add(size=6.0, location=(0.0, 2.0, 1.0),
                                         rotation=(np.pi / 2, 0.0, 0.0))
        plane = bpy.context.active_object
        mat = bpy.data.materials.new("Backdrop")
        mat.use_nodes = True
        nt = mat.node_tree
        checker = nt.nodes.new("ShaderNodeTexChecker")
        checker.inputs["Scale"].default_value = 12.0
        checker.inputs["Color1"].default_value = (0.3, 0.05, 0.05, 1.0)
        checker.inputs["Color2"].default_value = (0.05, 0.05, 0.3, 1.0)
        em = nt.nodes.new("ShaderNodeEmission")
        nt.links.new(checker.outputs["Color"], em.inputs["Color"])
        nt.links.new(em.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
        plane.data.materials.append(mat)


def render(path):
    setup_render(path)
    bpy.ops.render.render(write_still=True)
    return image_pixels(path)


class StreakSurfacesTest(unittest.TestCase):
    """One bake shared by the tests (a 50³ bake of 40 frames takes a while on 2 cores)."""

    @classmethod
    def setUpClass(cls):
        reset_scene()
        cls.tmp = temp_dir("plume_streaks_")
        cls.cache = os.path.join(cls.tmp, "cache")
        cls.dom = build_scene(cls.cache)
        t0 = time.perf_counter()
        assert bpy.ops.plume.bake() == {'FINISHED'}
        print(f"  bake took {time.perf_counter() - t0:.1f} s")
        cls.folder = os.path.join(cls.cache, "Domain")

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def setUp(self):
        select_only(bpy.data.objects["Domain"])
        bpy.context.scene.frame_set(1)

    def build(self):
        t0 = time.perf_counter()
        self.assertEqual(bpy.ops.plume.surfaces_build(), {'FINISHED'})
        print(f"  surfaces_build took {time.perf_counter() - t0:.2f} s")
        return surface_objects()

    def test_1_streak_files_written(self):
        from plume import _native
        for f in range(1, FRAMES + 1):
            self.assertTrue(os.path.isfile(os.path.join(self.folder, f"streaks_{f:04d}.bin")), f)
        snap = _native.read_streak_file(os.path.join(self.folder, f"streaks_{FRAMES:04d}.bin"))
        self.assertEqual(len(snap["counts"]) % POINT_SOURCES, 0)
        self.assertGreaterEqual(len(snap["counts"]), POINT_SOURCES)
        self.assertGreater(int(snap["counts"][0]), FRAMES)  # one particle per step
        # The last frame's checkpoints, solver and tracers together (resume, test_streak_sources).
        for name in ("state.bin", "tracer_state.bin"):
            self.assertTrue(os.path.isfile(os.path.join(self.folder, name)), name)

    def test_2_build_and_frame_change(self):
        obs = self.build()  # default h0 (mean of h): one cell's streaklines chain into one sheet
        self.assertGreaterEqual(len(obs), 1)
        # The artist lowers h0 watching the panel's live count (h cached by the first build).
        from plume.operators.surfaces import cached_distances, live_summary
        dom = bpy.data.objects["Domain"]
        groups = cached_distances(dom)
        self.assertIsNotNone(groups)
        h = np.concatenate([g.h.pairs()[2] for g in groups.values()])  # every h below the mean
        for q in (30, 20, 10, 5):
            dom.plume.domain.streak_threshold = float(np.percentile(h, q))
            n_surfaces, n_lines = live_summary(dom)
            print(f"  h0 = {q}th percentile of h: {n_surfaces} surfaces from {n_lines} streaklines")
            if n_surfaces >= 2:
                break
        self.assertGreaterEqual(n_surfaces, 2)
        obs = self.build()
        self.assertEqual(len(obs), n_surfaces, [o.name for o in obs])
        coll = bpy.data.collections.get("Domain_surfaces")
        self.assertIsNotNone(coll)
        self.assertEqual(set(coll.objects), set(obs))
        from plume import _native
        last = _native.read_streak_file(os.path.join(self.folder, f"streaks_{FRAMES:04d}.bin"))
        for ob in obs:
            sp = ob.data.splines[0]
            self.assertEqual(len(ob.data.splines), 1)
            self.assertGreaterEqual(sp.point_count_v, 2)
            # A least-squares net (test_streak_net.py): cubic along the streaklines, at most one
            # control point per particle.
            self.assertGreaterEqual(sp.point_count_u, 4)
            self.assertLessEqual(sp.point_count_u, int(np.max(last["counts"])))
            self.assertTrue(ob.data.materials[0].name.startswith("Plume Smoke Sheet"))
        # Fixed net, points follow the cache on frame changes.
        from plume.build import surfaces as build
        scn = bpy.context.scene
        before = {}
        for ob in obs:
            co = np.empty(len(ob.data.splines[0].points) * 4, np.float32)
            ob.data.splines[0].points.foreach_get("co", co)
            before[ob.name] = co
        times = []
        for f in range(25, 31):
            scn.frame_set(f)
            self.assertEqual(len(build.last_update_seconds), len(obs))
            times += build.last_update_seconds
        print(f"  per-surface update: max {max(times) * 1e3:.3f} ms, "
              f"mean {np.mean(times) * 1e3:.3f} ms")  # printed, not asserted: shared machines
        for ob in obs:
            co = np.empty(len(ob.data.splines[0].points) * 4, np.float32)
            ob.data.splines[0].points.foreach_get("co", co)
            self.assertEqual(co.shape, before[ob.name].shape)
            self.assertGreater(np.abs(co - before[ob.name]).max(), 0.05, ob.name)
        # The evaluated surface moved too (the depsgraph saw the update).
        dg = bpy.context.evaluated_depsgraph_get()
        top = max(max((ob.evaluated_get(dg).matrix_world @ __import__("mathutils").Vector(c)).z
                      for c in ob.evaluated_get(dg).bound_box) for ob in obs)
        self.assertGreater(top, 0.5)

    def test_2b_most_surfaces_threshold(self):
        """plume.surfaces_pick_threshold sets the h0 of the peak of the Figure-4 curve: no h0 up
        to the mean of h, where every pair below is held (checked just above and below every
        value of h there), gives more surfaces; above it the count is not claimed."""
        from plume import _native
        from plume import streak_surfaces as ss
        from plume.operators.surfaces import compute_distances
        dom = bpy.data.objects["Domain"]
        self.assertEqual(bpy.ops.plume.surfaces_pick_threshold(), {'FINISHED'})
        h0 = dom.plume.domain.streak_threshold
        groups = compute_distances(dom)[3]
        best = ss.summary(_native, groups, h0)
        print(f"  most surfaces: h0 = {h0:.4g} -> {best[0]} surfaces, {best[1]} streaklines")
        self.assertGreaterEqual(best[0], 2)
        reach = min(g.h.reach for g in groups.values())
        self.assertEqual(reach, min(g.h.mean for g in groups.values()))
        h = np.concatenate([g.h.pairs()[2] for g in groups.values()])
        for v in np.unique(h):
            for t in (v * (1 + 1e-6), v * (1 - 1e-6)):
                if 0 < t <= reach:
                    self.assertLessEqual(ss.summary(_native, groups, t)[0], best[0], t)
        with self.assertRaisesRegex(ValueError, "above the reach"):
            ss.summary(_native, groups, 1.5 * reach)

    def test_2c_threshold_above_the_mean(self):
        """An explicit h0 above the mean of h: the panel has no count until a build holds the
        pairs up to it (the build widens the cached distances), then counts live again."""
        from plume.operators.surfaces import cached_distances, live_summary
        dom = bpy.data.objects["Domain"]
        d = dom.plume.domain
        self.build()  # caches the distances up to the default h0
        mean = min(g.h.mean for g in cached_distances(dom).values())
        try:
            d.streak_threshold = 1.5 * mean
            self.assertIsNone(live_summary(dom))
            obs = self.build()
            counts = live_summary(dom)
            self.assertIsNotNone(counts)
            self.assertEqual(counts[0], len(obs))
        finally:
            d.streak_threshold = 0.0

    def test_3_render_is_semi_transparent(self):
        if not surface_objects():
            self.build()
        os.makedirs(OUT_DIR, exist_ok=True)
        scn = bpy.context.scene
        scn.frame_set(FRAMES)
        with_sheets = render(os.path.join(OUT_DIR, "streak_surfaces.png"))
        for ob in surface_objects():
            ob.hide_render = True
        try:
            empty = render(os.path.join(OUT_DIR, "streak_surfaces_empty.png"))
        finally:
            for ob in surface_objects():
                ob.hide_render = False
        diff = np.abs(with_sheets[..., :3] - empty[..., :3]).max(axis=-1)
        covered = diff > 4 / 255
        share = covered.mean()
        print(f"  pixels changed by the sheets: {share:.3%}")
        # Measured 1.73% (3.4.1) and 1.66% (5.3.0): the sheets are thin, 1% says they show.
        self.assertGreater(share, 0.01, "the sheets do not show")
        # Semi-transparent: the checker backdrop still shows through covered pixels, so their
        # red/blue contrast survives partly; and the changes span a range of strengths.
        vals = diff[covered]
        levels = np.unique(np.round(vals * 255))
        print(f"  change strengths: {np.percentile(vals, [5, 50, 95])}, {len(levels)} levels")
        self.assertGreater(len(levels), 10)
        bg_contrast = np.abs(empty[..., 0] - empty[..., 2])
        fg_contrast = np.abs(with_sheets[..., 0] - with_sheets[..., 2])
        see_through = covered & (bg_contrast > 0.05) & (fg_contrast > 0.2 * bg_contrast)
        print(f"  covered pixels where the backdrop shows through: "
              f"{see_through.sum() / max(covered.sum(), 1):.1%}")
        # Measured 75.7% (3.4.1) and 67.1% (5.3.0) of the covered pixels: at least half, the
        # margin covering the Blenders' own differences in transparency sampling.
        self.assertGreater(see_through.sum(), 0.5 * covered.sum(),
                           "too little of the backdrop shows through the sheets")
        self.assertLess(vals.min(), 0.5 * vals.max())

    # ------------------------------------------------------------------- bad input
    def assert_error(self, pattern):
        assert_reports_error(self, bpy.ops.plume.surfaces_build, pattern, counts)

    def test_4_negative_threshold(self):
        d = bpy.data.objects["Domain"].plume.domain
        d.streak_threshold = -1.0
        try:
            self.assert_error(r"Threshold \(h0\) \(Physics Properties › Plume › Streak "
                              r"Surfaces\) must be >= 0 \(0 = the mean .*; got -1(\.0)?\)")
        finally:
            d.streak_threshold = 0.0

    def test_5_negative_sampling(self):
        d = bpy.data.objects["Domain"].plume.domain
        d.density_k_u = -1
        try:
            self.assert_error(r"Sampling u \(k_u\) \(Physics Properties › Plume › Streak "
                              r"Surfaces\) must be >= 0 \(samples between particles, §3\.4; "
                              r"got -1\)")
        finally:
            d.density_k_u = 4

    def test_6_missing_streak_file(self):
        path = os.path.join(self.folder, "streaks_0010.bin")
        keep = path + ".keep"
        os.rename(path, keep)
        try:
            self.assert_error(r"streaks_0010\.bin is missing")
        finally:
            os.rename(keep, path)


class StreakBadInputTest(unittest.TestCase):
    def setUp(self):
        reset_scene()
        self.tmp = temp_dir("plume_streaks_bad_")
        self.cache = os.path.join(self.tmp, "cache")

    def tearDown(self):
        rmtree(self.tmp)

    def assert_error(self, pattern):
        assert_reports_error(self, bpy.ops.plume.surfaces_build, pattern, counts)

    def test_no_bake_yet(self):
        build_scene(self.cache, frame_end=3)
        self.assert_error(r"has no bake yet")
        # The Most Surfaces button needs the bake too, and leaves h0 as it was.
        h0 = bpy.data.objects["Domain"].plume.domain.streak_threshold
        assert_reports_error(self, bpy.ops.plume.surfaces_pick_threshold, r"has no bake yet",
                             counts)
        self.assertEqual(bpy.data.objects["Domain"].plume.domain.streak_threshold, h0)

    def test_baked_without_streaks(self):
        build_scene(self.cache, frame_end=2, streaks=False)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        self.assert_error(r"baked without streak surfaces: turn on Streak Surfaces "
                          r"\(Physics Properties › Plume › Streak Surfaces\)")

    def test_group_with_one_source(self):
        build_scene(self.cache, frame_end=2, point_sources=1)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        self.assert_error(r"candidate group 0 has a single point source.*raise the source's "
                          r"Point Sources")

    def test_bad_emission_period_writes_nothing(self):
        dom = build_scene(self.cache, frame_end=2)
        dom.plume.domain.emission_period = 0
        with self.assertRaises(RuntimeError) as ctx:
            bpy.ops.plume.bake()
        self.assertIn("Emission Period (Physics Properties › Plume › Streak Surfaces) must be in "
                      "[1, 100000]", str(ctx.exception))
        self.assertFalse(os.path.exists(self.cache))


if __name__ == "__main__":
    run(StreakSurfacesTest, StreakBadInputTest)
