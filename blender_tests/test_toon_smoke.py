"""Toon smoke end to end ([Cartoon Smoke] §2): a small bake (24³, 20 frames), then
plume.toon_build makes a point object that follows toon_####.bin on frame changes, billboards
with a stencil cut-out, and the "Plume Depth Differences" compositor group. A 320x240 Cycles
render saves the Depth pass and the group's outline as 32-bit EXR: the outline equals
_native.depth_differences on the same depth in >= 99.9% of the pixels, outline pixels exist and
the interior is flat-coloured. Bad input (no cache, γ < 0, missing stencil image, no camera)
gives a clear error and changes nothing.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_toon_smoke.py
"""

import os
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import (OUT_DIR, add_domain, compat, add_sphere_source, assert_reports_error,  # noqa: E402
                     image_pixels, native, reset_scene, rmtree, run, select_only, temp_dir,
                     tree_listing)

RESOLUTION = 24
FRAMES = 20
RENDER_FRAME = 16
GAMMA = 0.05
LOW, HIGH = (0.1, 0.3, 0.8, 1.0), (0.9, 0.6, 0.1, 1.0)  # linear ramp colours (distinct from bg)
WORLD = (0.02, 0.02, 0.02, 1.0)


def build_scene(cache_dir, camera=True):
    src = add_sphere_source(radius=0.25, location=(0.0, 0.0, 0.4))
    src.plume.source.velocity = (0.0, 0.0, 1.0)
    src.plume.source.density = 2.0
    dom = add_domain(resolution=RESOLUTION, frame_end=FRAMES, cache_directory=cache_dir + "/")
    t = dom.plume.domain.toon
    t.birth_density, t.death_density = 0.3, 0.05
    t.size_low, t.size_high = 0.08, 0.2
    t.max_size_change = 0.5
    t.depth_threshold = GAMMA
    # 14 px at 1080 lines is 3.1 px at 240: the line covers the band of §2.2's test in full
    # (its soft edge lies on the next pixels out, which the interior check leaves out).
    t.outline_width = 14.0
    t.stencil = 'PUFFY'
    t.ramp_color_low, t.ramp_color_high = LOW, HIGH
    scn = bpy.context.scene
    if camera:
        cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
        scn.collection.objects.link(cam)
        cam.location = (0.0, -3.2, 1.0)
        cam.rotation_euler = (np.pi / 2, 0.0, 0.0)
        scn.camera = cam
    scn.frame_start, scn.frame_end = 1, FRAMES
    select_only(dom)
    return dom


def state(folder):
    """Everything plume.toon_build may change: datablocks, scene settings, cache files."""
    scn = bpy.context.scene
    return (len(bpy.data.objects), len(bpy.data.meshes), len(bpy.data.materials),
            len(bpy.data.images), len(bpy.data.node_groups), compat.compositor_tree(scn) is not None,
            bpy.context.view_layer.use_pass_z, scn.render.use_lock_interface,
            tuple(tree_listing(folder)))


def assert_billboards_follow_camera(test, ob, snap, stretch_factor):
    """The evaluated billboards are Figure 4 for the scene camera as it is at the current frame:
    quad n (vertices 4n..4n+3 of a 2x2 grid, realized in point order) has its local x edge
    (vertex 4n+2 - 4n) along _native.toon_billboards' axis with length size * stretch, and its
    y edge size long. Float32 nodes against the float64 reference: 1e-4 relative."""
    scn = bpy.context.scene
    n = len(snap["ids"])
    b = native().toon_billboards(np.array(scn.camera.matrix_world), True, snap["positions"],
                                 snap["velocities"], stretch_factor)
    ev = ob.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    test.assertEqual(len(ev.vertices), 4 * n)  # one realized quad per point
    co = np.empty(3 * len(ev.vertices), np.float32)
    ev.vertices.foreach_get("co", co)
    quads = co.reshape(n, 4, 3).astype(np.float64)
    ex, ey = quads[:, 2] - quads[:, 0], quads[:, 1] - quads[:, 0]
    size = np.asarray(snap["size"], np.float64)
    grown = size > 1e-3  # a particle being born or dying has a degenerate quad
    test.assertGreater(int(grown.sum()), 10)
    lx, ly = np.linalg.norm(ex, axis=1), np.linalg.norm(ey, axis=1)
    np.testing.assert_allclose(lx[grown], (size * np.asarray(b["stretch"]))[grown], rtol=1e-4)
    np.testing.assert_allclose(ly[grown], size[grown], rtol=1e-4)
    cosine = np.sum(ex[grown] * np.asarray(b["axis"], np.float64)[grown], axis=1) / lx[grown]
    test.assertGreater(float(cosine.min()), 1.0 - 1e-4)


class ToonSmokeTest(unittest.TestCase):
    """One bake shared by the tests; each test starts from a fresh scene on the same cache."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = temp_dir("plume_toon_")
        cls.cache = os.path.join(cls.tmp, "cache")
        cls.folder = os.path.join(cls.cache, "Domain")

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def scene(self, camera=True, bake=True):
        reset_scene()
        dom = build_scene(self.cache, camera=camera)
        if bake:
            t0 = time.perf_counter()
            self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})  # same settings: reused
            print(f"  bake: {time.perf_counter() - t0:.1f} s")
            select_only(dom)
        return dom

    def build(self):
        t0 = time.perf_counter()
        self.assertEqual(bpy.ops.plume.toon_build(), {'FINISHED'})
        print(f"  toon_build: {time.perf_counter() - t0:.2f} s")
        return bpy.data.objects["Domain_toon"]

    def test_0_source_cells(self):
        """§2.1: particles are introduced at the source: the cells handed to the runner are the
        source sphere's cells of the bake grid (centres inside radius + half a cell diagonal)."""
        dom = self.scene()
        from plume import cache, toon
        from plume.snapshot import emitter_snapshots
        from plume.toon_sources import ToonSourceCells
        m = cache.read_manifest(self.folder)
        cells = ToonSourceCells(native(), toon.toon_grid(m),
                                emitter_snapshots(bpy.context, dom, 1, 1), 1).cells_at(1)
        self.assertIsNotNone(cells)
        self.assertGreater(len(cells), 4)
        h = float(m["cell_size"])
        centres = np.asarray(m["origin"]) + (cells + 0.5) * h
        dist = np.linalg.norm(centres - np.array([0.0, 0.0, 0.4]), axis=1)
        self.assertLessEqual(dist.max(), 0.25 + 0.87 * h)
        self.assertTrue(np.all(cells >= 0) and np.all(cells < np.asarray(m["resolution"])))

    def test_1_points_follow_cache(self):
        dom = self.scene()
        ob = self.build()
        for f in range(1, FRAMES + 1):
            self.assertTrue(os.path.isfile(os.path.join(self.folder, f"toon_{f:04d}.bin")), f)
        from plume.build import toon_points
        scn = bpy.context.scene
        for f in (5, RENDER_FRAME):
            scn.frame_set(f)
            self.assertEqual(len(toon_points.last_update_seconds), 1)
            snap = native().read_toon_file(os.path.join(self.folder, f"toon_{f:04d}.bin"))
            n = len(snap["ids"])
            self.assertGreater(n, 10, f)
            me = ob.data
            self.assertEqual(len(me.vertices), n)
            co = np.empty(3 * n, np.float32)
            me.vertices.foreach_get("co", co)
            np.testing.assert_array_equal(co.reshape(n, 3), snap["positions"])
            size = np.empty(n, np.float32)
            me.attributes["size"].data.foreach_get("value", size)
            np.testing.assert_array_equal(size, snap["size"])
            for name in ("plume_velocity", "plume_color", "id"):
                self.assertIn(name, me.attributes)
            assert_billboards_follow_camera(self, ob, snap, 0.5)
        print(f"  handler update: {toon_points.last_update_seconds[0] * 1e3:.2f} ms "
              f"for {n} points")
        # An animated camera: the billboards follow the camera of the frame drawn (the handler
        # runs before the frame's camera is evaluated, so the group reads the camera itself).
        cam = scn.camera
        for f, x, yaw in ((4, -1.0, -0.4), (6, 1.2, 0.5)):
            cam.location.x, cam.rotation_euler.z = x, yaw
            cam.keyframe_insert("location", frame=f)
            cam.keyframe_insert("rotation_euler", frame=f)
        for f in (4, 5, 6):
            scn.frame_set(f)
            snap = native().read_toon_file(os.path.join(self.folder, f"toon_{f:04d}.bin"))
            assert_billboards_follow_camera(self, ob, snap, 0.5)
        # Look settings update the built smoke at once, without a rebuild.
        t = dom.plume.domain.toon
        t.stretch_factor = 1.5
        t.depth_threshold = 0.25
        t.ramp_color_high = (0.2, 0.9, 0.3, 1.0)
        assert_billboards_follow_camera(self, ob, snap, 1.5)
        group = compat.compositor_tree(scn).nodes["Plume Depth Differences"]
        self.assertAlmostEqual(group.inputs["Gamma"].default_value, 0.25, places=6)
        ramp = next(n for n in bpy.data.materials["Plume Toon Domain"].node_tree.nodes
                    if n.type == 'VALTORGB')
        np.testing.assert_allclose(tuple(ramp.color_ramp.elements[-1].color), (0.2, 0.9, 0.3, 1.0),
                                   atol=1e-6)
        t.stretch_factor, t.depth_threshold = 0.5, GAMMA
        self.assertEqual(ob.modifiers[0].node_group.name, "Plume Toon Billboards")
        mat = bpy.data.materials["Plume Toon Domain"]
        self.assertEqual(compat.transparency(mat), 'CLIP')
        self.assertEqual(bpy.context.view_layer.pass_alpha_threshold, 0.5)
        # The generated stencil is deterministic: a second build writes the same bytes.
        path = os.path.join(self.folder, "stencil_puffy.png")
        first = open(path, "rb").read()
        dom.plume.domain.toon.use_freestyle = True  # the optional Freestyle style
        self.build()
        self.assertEqual(open(path, "rb").read(), first)
        self.assertTrue(scn.render.use_freestyle)
        self.assertIn("Plume Toon", bpy.context.view_layer.freestyle_settings.linesets)
        # plume.cache_free removes the toon files with the rest of the bake.
        self.assertEqual(bpy.ops.plume.cache_free(), {'FINISHED'})
        self.assertFalse(os.path.exists(self.folder))

    def test_2_render_outlines_match_native(self):
        self.scene()
        self.build()
        self.build()  # an artist's rebuild: the compositor group must stay wired (it did not)
        scn = bpy.context.scene
        scn.render.engine = 'CYCLES'
        scn.cycles.device = 'CPU'
        scn.cycles.samples = 4
        scn.cycles.use_denoising = False
        scn.render.resolution_x, scn.render.resolution_y = 320, 240
        scn.render.resolution_percentage = 100
        scn.view_settings.view_transform = 'Standard'
        if scn.world is None:
            scn.world = bpy.data.worlds.new("World")
        scn.world.use_nodes = True
        scn.world.node_tree.nodes["Background"].inputs["Color"].default_value = WORLD
        bpy.data.objects["Domain"].hide_render = True
        bpy.data.objects.get("Domain_smoke") and setattr(
            bpy.data.objects["Domain_smoke"], "hide_render", True)
        nt = compat.compositor_tree(scn)
        group = nt.nodes["Plume Depth Differences"]
        self.assertEqual(group.node_tree.name, "Plume Depth Differences")
        rl = next(n for n in nt.nodes if n.type == 'R_LAYERS')
        out = os.path.join(OUT_DIR, "toon")
        os.makedirs(out, exist_ok=True)
        compat.compositor_file_output(nt, out, "depth", rl.outputs["Depth"])
        compat.compositor_file_output(nt, out, "outline", group.outputs["Outline"])
        compat.compositor_file_output(nt, out, "image", group.outputs["Image"])
        scn.frame_set(RENDER_FRAME)
        scn.render.filepath = os.path.join(out, "toon.png")
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        print(f"  render 320x240: {time.perf_counter() - t0:.1f} s")
        depth = image_pixels(os.path.join(out, f"depth{RENDER_FRAME:04d}.exr"))[..., 0]
        outline = image_pixels(os.path.join(out, f"outline{RENDER_FRAME:04d}.exr"))[..., 0]
        image = image_pixels(os.path.join(out, f"image{RENDER_FRAME:04d}.exr"))[..., :3]
        far = scn.camera.data.clip_end
        smoke = depth < far
        self.assertGreater(smoke.mean(), 0.01)  # billboards cover part of the frame
        ref = native().depth_differences(np.ascontiguousarray(depth), GAMMA)
        agree = float(np.mean((outline > 0.5) == (ref == 1)))
        print(f"  outline pixels: {int((outline > 0.5).sum())} compositor, {int(ref.sum())} "
              f"native, agreement {agree * 100:.3f}%; smoke pixels {int(smoke.sum())}")
        self.assertGreaterEqual(agree, 0.999)
        self.assertGreater(int(ref.sum()), 50)
        # Outline pixels carry the outline colour (black).
        self.assertLess(float(np.abs(image[outline > 0.5]).max()), 1e-6)
        # Interior (smoke, >= 2 px from any outline): flat colours on the ramp low..high; the
        # only mixing is the pixel filter across two stencils, which stays on the ramp segment.
        edge = outline > 0.5
        near = edge.copy()
        for dy in range(-2, 3):
            for dx in range(-2, 3):
                near |= np.roll(np.roll(edge, dy, 0), dx, 1)
        interior = smoke & ~near
        self.assertGreater(int(interior.sum()), 100)
        lo, hi = np.array(LOW[:3]), np.array(HIGH[:3])
        d = hi - lo
        px = image[interior]
        t = np.clip((px - lo) @ d / (d @ d), 0.0, 1.0)
        dist = np.linalg.norm(px - (lo + t[:, None] * d), axis=1)
        print(f"  interior pixels {len(px)}: max distance to the ramp {dist.max():.4f}, ramp "
              f"position percentiles 5/50/95: {np.percentile(t, [5, 50, 95]).round(3)}")
        self.assertLess(float(np.percentile(dist, 99)), 0.02)
        # The ramp is driven by the particles' values (density here), not stuck at one end:
        # the visible colours span much of the range the particles' ramp coordinates span.
        ob = bpy.data.objects["Domain_toon"]
        c = np.empty(len(ob.data.vertices), np.float32)
        ob.data.attributes["plume_color"].data.foreach_get("value", c)
        spread = float(np.percentile(t, 95) - np.percentile(t, 5))
        print(f"  particle ramp coordinates {c.min():.3f}..{c.max():.3f}, pixel spread {spread:.3f}")
        self.assertGreater(spread, 0.25 * float(c.max() - c.min()))

    def test_3_bad_input_changes_nothing(self):
        dom = self.scene(bake=False)
        d = dom.plume.domain
        empty = os.path.join(self.tmp, "empty")
        d.cache_directory = empty + "/"
        op = bpy.ops.plume.toon_build
        assert_reports_error(self, op, "has no bake yet", lambda: state(empty))
        self.assertFalse(os.path.exists(empty))
        d.cache_directory = self.cache + "/"
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        select_only(dom)
        d.toon.depth_threshold = -0.1
        assert_reports_error(self, op, r"Depth Threshold \(γ\) \(Physics Properties › Plume › "
                             r"Toon Smoke\) must be >= 0, .* \(§2\.2; got -0\.1\)",
                             lambda: state(self.folder))
        d.toon.depth_threshold = GAMMA
        d.toon.stencil = 'IMAGE'
        d.toon.stencil_image = os.path.join(self.tmp, "no_such_stencil.png")
        assert_reports_error(self, op, r"Stencil Image \(Physics Properties › Plume › Toon "
                             r"Smoke\) .*no_such_stencil\.png does not exist: pick an image file",
                             lambda: state(self.folder))
        d.toon.stencil_image = ""
        assert_reports_error(self, op, r"Stencil is Image but Stencil Image \(Physics "
                             r"Properties › Plume › Toon Smoke\) is empty",
                             lambda: state(self.folder))
        d.toon.stencil = 'CIRCLE'
        d.toon.birth_density = 0.01
        assert_reports_error(self, op, r"Death Density \(ρ_death\) \(Physics Properties › "
                             r"Plume › Toon Smoke\) must be >= 0 and below Birth Density "
                             r"\(ρ_birth\) \(got 0\.05 and 0\.01\)", lambda: state(self.folder))
        d.toon.birth_density = 0.3
        d.toon.birth_spacing = -0.5
        assert_reports_error(self, op, r"Birth Spacing \(σ\) \(Physics Properties › Plume › "
                             r"Toon Smoke\) must be in \[0, 10\] stencil sizes.*\(got -0\.5\)",
                             lambda: state(self.folder))
        d.toon.birth_spacing = 0.5
        cam = bpy.context.scene.camera
        bpy.context.scene.camera = None
        assert_reports_error(self, op, r"has no camera.*add a camera \(Add › Camera\) and make "
                             r"it the scene's camera \(Scene Properties › Scene › Camera\)",
                             lambda: state(self.folder))
        bpy.context.scene.camera = cam
        self.assertEqual(op(), {'FINISHED'})  # and with good input it builds


if __name__ == "__main__":
    run(ToonSmokeTest)
