"""Structural flames end to end ([Structural Flames]), through the operators: a candle
(1 flame, CANDLE profile) and a torch (5 flames, TORCH profile) bake 12 frames with
plume.flames_bake; the VDBs hold the named grids, the spines curve has one spline per live flame
through that flame's points, the lights exist with energy > 0, and Cycles renders the flames
non-empty. Bad input (no flame source, n < 2, H_p >= H_i, a noise setting out of range, a Custom
profile with no curve, a missing image file) gives an error naming the setting and changes
nothing. The noises' settings reach the bake: the spine's Kolmogorov noise moves the control
points, the render noise the VDB.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_flames.py
"""

import os
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import (OUT_DIR, compat, assert_reports_error, flame_studio, image_pixels,  # noqa: E402
                     native, reset_scene, rmtree, run, run_cancelled, select_only, temp_dir,
                     tree_listing)

FRAMES = 12
GRIDS = {"emission", "density", "temperature", "flame", "color", "velocity"}
OBSTACLE_FRAMES = 8
KEY_FRAMES = 16
#: (lower, upper) corners of the plate over the candle (m): 2 cm thick, 1 cm above the wick.
PLATE = ((-0.04, -0.04, 0.02), (0.04, 0.04, 0.04))


def box_distance(points, lo, hi):
    """Exact signed distance (m, < 0 inside) of points (N, 3) to the box [lo, hi]."""
    q = np.abs(points - (lo + hi) / 2) - (hi - lo) / 2
    return np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)


#: The torch scene's structure and noise settings (the Flames defaults until issue 30).
TORCH_SETTINGS = dict(points=16, lifespan_scale=0.25, breakaway_frequency=0.0, buoyancy=0.5,
                      diffusion=1e-4, flow_noise=0.15, kolmogorov=0.003, spine_noise=0.04)


def flame_scene(tmp, flames=1, profile='CANDLE'):
    """A wick (candle) or a torch head as a Flame Source, a camera looking at it, black world."""
    reset_scene()
    scn = bpy.context.scene
    if flames == 1:
        bpy.ops.mesh.primitive_cylinder_add(radius=0.002, depth=0.01, location=(0, 0, 0.005))
    else:
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.04, location=(0, 0, 0.0))
    src = bpy.context.active_object
    src.name = "Candle" if flames == 1 else "Torch"
    bpy.ops.plume.role_set(role='FLAME_SOURCE')
    fl = src.plume.flame
    fl.profile, fl.flames = profile, flames
    fl.radius = 0.006 if flames == 1 else 0.02
    f = scn.plume_flames
    f.frame_start, f.frame_end = 1, FRAMES
    f.cache_directory = tmp + "/"
    if flames == 1:
        f.height_persistent, f.height_intermittent, f.height_max = 0.03, 0.05, 0.08
        f.voxel_size = 0.001
    else:
        f.height_persistent, f.height_intermittent, f.height_max = 0.08, 0.16, 0.3
        f.voxel_size = 0.003
        # The torch keeps the settings its tests were measured with (the Flames defaults before
        # they became the Candle preset's).
        for name, value in TORCH_SETTINGS.items():
            setattr(f, name, value)
    dist = 0.35 if flames == 1 else 1.0
    flame_studio(scn, (0.0, -dist, 0.04 if flames == 1 else 0.12), 120, 160, 8)
    src.hide_render = True
    select_only(src)
    return src


class FlamesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = temp_dir("plume_flames_")

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def bake_and_check(self, name, flames):
        folder = os.path.join(self.tmp, name)
        flame_scene(folder, flames=flames, profile='CANDLE' if flames == 1 else 'TORCH')
        scn = bpy.context.scene
        t0 = time.perf_counter()
        self.assertEqual(bpy.ops.plume.flames_bake(), {'FINISHED'})
        seconds = time.perf_counter() - t0
        print(f"  {name}: {seconds / FRAMES:.3f} s/frame; {scn.plume_flames.summary}")
        files = sorted(os.listdir(folder))
        for frame in range(1, FRAMES + 1):
            self.assertIn(f"flames_{frame:04d}.vdb", files)
            self.assertIn(f"spines_{frame:04d}.npz", files)
        self.assertFalse([n for n in files if n.endswith(".tmp")])
        vdb = os.path.join(folder, f"flames_{FRAMES:04d}.vdb")
        self.assertTrue(GRIDS <= set(native().vdb_grid_names(vdb)))
        density = native().read_vdb_grid(vdb, "density")
        self.assertGreater(float(np.asarray(density["values"]).max()), 0.0)
        # The spines curve at the last frame: one spline per live flame through its points.
        scn.frame_set(FRAMES)
        from plume import flames as flames_mod
        sp = flames_mod.read_spines(os.path.join(folder, f"spines_{FRAMES:04d}.npz"))
        live = len(sp["ids"])
        self.assertGreaterEqual(live, flames)  # every source has its attached flame
        attached = sp["counts"][~sp["separated"]]
        self.assertTrue(np.all(attached == scn.plume_flames.points))
        curve = bpy.data.objects[scn.plume_flames.spines_object]
        self.assertEqual(len(curve.data.splines), live)
        start = 0
        for spline, count in zip(curve.data.splines, sp["counts"]):
            co = np.array([p.co[:3] for p in spline.points])
            np.testing.assert_allclose(co, sp["points"][start:start + count], atol=1e-6)
            start += count
        # A spine rises from its source (buoyancy, eq. 2): the tip is above the base.
        base, tip = sp["points"][0], sp["points"][sp["counts"][0] - 1]
        self.assertGreater(tip[2], base[2] + 0.01)
        # Lights (§5.2): one per live flame, radius h/3, energy of eq. 5 > 0.
        lights = [o for o in scn.objects if o.type == 'LIGHT' and "plume_flame_light" in o]
        on = [o for o in lights if o.data.energy > 0.0]
        self.assertEqual(len(on), live)
        self.assertTrue(all(o.data.shadow_soft_size > 0.0 for o in on))
        # Render: the flames show.
        out = os.path.join(OUT_DIR, "flames")
        os.makedirs(out, exist_ok=True)
        scn.render.filepath = os.path.join(out, f"{name}.png")
        bpy.ops.render.render(write_still=True)
        px = image_pixels(scn.render.filepath)[..., :3]
        lit = float((px.max(axis=2) > 0.05).mean())
        print(f"  {name} render: max {px.max():.3f}, lit pixels {lit * 100:.1f}%")
        # Measured in 3.4.1: candle 4.9% (8.5-9.3% before the Flames defaults became the Candle
        # preset's: calmer noise, and separated tips thin to wisps), torch 15.2% (3.4.1-5.3
        # before: 15.3-18.6%); the floors leave a third for the Blenders' differences and say the
        # flame fills its part of the frame.
        self.assertGreater(lit, {"candle": 0.033, "torch": 0.10}[name])
        return sp

    def test_candle(self):
        self.bake_and_check("candle", 1)

    def test_torch(self):
        sp = self.bake_and_check("torch", 5)
        self.assertEqual(len(set(sp["sources"][~sp["separated"]])), 5)

    def test_free(self):
        folder = os.path.join(self.tmp, "free")
        flame_scene(folder)
        bpy.context.scene.plume_flames.frame_end = 2
        self.assertEqual(bpy.ops.plume.flames_bake(), {'FINISHED'})
        self.assertEqual(bpy.ops.plume.flames_free(), {'FINISHED'})
        self.assertEqual(tree_listing(folder), [])
        self.assertIsNone(bpy.data.objects.get("Plume Flames"))
        self.assertIsNone(bpy.data.objects.get("Plume Flame Spines"))

    def test_cancelled_keeps_finished_frames(self):
        """Bake Flames cancelled after two frames (from its progress report, as Esc does in the
        UI): like a smoke bake it keeps and builds the frames it finished, and no partial file.
        The cancel reaches the child while it computes the next frame, which it finishes (a
        unit of work): two or three frames. The torch: its frames take ~0.1 s, longer than the
        cancel's round trip (the candle's first frames, a few small flames since the Candle
        defaults, take a few ms: four frames finished before the cancel landed)."""
        from plume.operators.flames import FlamesJob, PLUME_OT_flames_bake
        folder = os.path.join(self.tmp, "cancelled")
        flame_scene(folder, flames=5, profile='TORCH')
        job = FlamesJob()
        self.assertEqual(run_cancelled(PLUME_OT_flames_bake, job, after=2), {'FINISHED'})
        self.assertTrue(job.result.cancelled)
        f = bpy.context.scene.plume_flames
        self.assertIn(f.frames_baked, (2, 3))
        done = f.frames_baked
        self.assertEqual([n for n in tree_listing(folder) if not n.endswith(".json")],
                         [f"flames_{i:04d}.vdb" for i in range(1, done + 1)]
                         + [f"spines_{i:04d}.npz" for i in range(1, done + 1)])
        self.assertIsNotNone(bpy.data.objects.get(f.volume_object))
        from plume.operators.flames import is_baking
        self.assertFalse(is_baking())

    def test_placement(self):
        """Flames are placed on the mesh's up-facing faces, apart, the same for a seed."""
        from plume import flame_placement as place
        reset_scene()
        bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0)
        from plume.snapshot import mesh_arrays
        v, t = mesh_arrays(bpy.context.active_object, bpy.context.evaluated_depsgraph_get())
        v = v.astype(np.float64)
        faces, bary = place.place_flames(v, t, 5, seed=3)
        again = place.place_flames(v, t, 5, seed=3)
        np.testing.assert_array_equal(faces, again[0])
        pts = place.interpolate(v[t], faces, bary)
        self.assertTrue(np.all(pts[:, 2] > 0.0))  # upper half
        gaps = np.linalg.norm(pts[:, None] - pts[None], axis=2) + np.eye(5) * 9
        self.assertGreater(gaps.min(), 0.3)
        # The same places whatever order Blender lists the faces in (canonical order).
        perm = np.random.default_rng(1).permutation(len(t))
        a, b = t[place.canonical_order(t)], t[perm][place.canonical_order(t[perm])]
        np.testing.assert_allclose(place.interpolate(v[a], *place.place_flames(v, a, 5, 3)),
                                   place.interpolate(v[b], *place.place_flames(v, b, 5, 3)))
        one = place.interpolate(v[t], *place.place_flames(v, t, 1, seed=0))[0]
        self.assertGreater(one[2], 0.95)  # the top of the sphere

    def test_obstacle(self):
        """§6.1: a plate over the candle. Without obstacles the flames burn through it (the
        control bake: density inside it); with them no spine point ends inside it and no
        rendered density lies inside it."""
        from plume import flames as flames_mod
        folder = os.path.join(self.tmp, "obstacle")
        src = flame_scene(folder)
        scn = bpy.context.scene
        scn.plume_flames.frame_end = OBSTACLE_FRAMES
        lo, hi = np.array(PLATE[0]), np.array(PLATE[1])
        bpy.ops.mesh.primitive_cube_add(size=1.0, location=tuple((lo + hi) / 2),
                                        scale=tuple(hi - lo))
        bpy.ops.plume.role_set(role='OBSTACLE')
        bpy.context.active_object.hide_render = True
        select_only(src)
        # Cells of the flame VDB deep inside the plate: the hat kernel of the raster spreads a
        # particle over the cells within one voxel of it, and the voxelized SDF (trilinear over
        # OBSTACLE_VOXEL cells) is exact on the plate's flat faces and errs by at most half a
        # cell at its edges, so particles kept (phi_grid >= 0) touch no cell deeper than
        # voxel + OBSTACLE_VOXEL / 2 inside the plate.
        deep = scn.plume_flames.voxel_size + 0.5 * flames_mod.OBSTACLE_VOXEL

        def inside_mass():
            total = 0.0
            for frame in range(1, OBSTACLE_FRAMES + 1):
                g = native().read_vdb_grid(flames_mod.volume_path(folder, frame), "density")
                vals = np.asarray(g["values"], np.float64)
                axes = [g["world_of_voxel_zero"][a] + (g["min"][a] + np.arange(vals.shape[a]))
                        * g["voxel_size"] for a in range(3)]
                inner = [(x > lo[a] + deep) & (x < hi[a] - deep) for a, x in enumerate(axes)]
                total += float(vals[np.ix_(*inner)].sum())
            return total

        scn.plume_flames.use_obstacles = False
        self.assertEqual(bpy.ops.plume.flames_bake(), {'FINISHED'})
        burnt = inside_mass()
        self.assertGreater(burnt, 0.0)  # the plate is in the flames' way
        scn.plume_flames.use_obstacles = True
        self.assertEqual(bpy.ops.plume.flames_bake(), {'FINISHED'})
        kept = inside_mass()
        low = np.inf
        for frame in range(1, OBSTACLE_FRAMES + 1):
            pts = flames_mod.read_spines(flames_mod.spines_path(folder, frame))["points"]
            low = min(low, float(box_distance(pts, lo, hi).min()))
        print(f"  obstacle: density inside the plate {burnt:.3g} -> {kept:.3g}; "
              f"lowest spine point distance {low * 1000:.2f} mm")
        self.assertEqual(kept, 0.0)
        # Points are pushed to phi_grid >= obstacle_margin (1 mm) > the grid's error at edges.
        self.assertGreaterEqual(low, 0.0)

    def test_spines_keyframes(self):
        """Bake Spines to Keyframes: one curve object per flame id whose point F-curves hold a
        key on every frame the flame lives, equal to the cached points (padded with the tip
        when it has fewer), hidden (viewport and render) on the baked frames it does not live."""
        from plume import flames as flames_mod
        from plume.build import flame_spine_keys as keys_mod
        folder = os.path.join(self.tmp, "keys")
        flame_scene(folder)
        scn = bpy.context.scene
        scn.plume_flames.frame_end = KEY_FRAMES
        scn.plume_flames.lifespan_scale = 0.1  # separated flames that are born and die
        op = bpy.ops.plume.flames_bake_spines_keyframes
        assert_reports_error(self, op, r"no flames are baked",
                             lambda: (len(bpy.data.objects), len(bpy.data.actions)))
        self.assertEqual(bpy.ops.plume.flames_bake(), {'FINISHED'})
        self.assertEqual(op(), {'FINISHED'})
        tracks = keys_mod.read_tracks(folder, 1, KEY_FRAMES)
        col = bpy.data.collections[keys_mod.COLLECTION_NAME]
        self.assertEqual(sorted(o[keys_mod.ID_KEY] for o in col.objects), sorted(tracks))
        mortal = 0
        for fid, by_frame in tracks.items():
            ob = bpy.data.objects[keys_mod.object_name(fid)]
            n = len(ob.data.splines[0].points)
            self.assertEqual(n, max(len(p) for p in by_frame.values()))
            fcs = {(fc.data_path, fc.array_index): fc
                   for fc in compat.fcurves(ob.data)}
            self.assertEqual(len(fcs), 3 * n)
            for frame, pts in by_frame.items():
                want = keys_mod.padded(pts, n)
                for k in range(n):
                    for c in range(3):
                        fc = fcs[(f"splines[0].points[{k}].co", c)]
                        key = [p for p in fc.keyframe_points if p.co[0] == frame]
                        self.assertEqual(len(key), 1)  # a key on the frame, the cached value
                        self.assertEqual(key[0].co[1], want[k, c])
            vis = {fc.data_path: fc for fc in compat.fcurves(ob)}
            for frame in range(1, KEY_FRAMES + 1):
                for path in ("hide_viewport", "hide_render"):
                    self.assertEqual(bool(vis[path].evaluate(frame)), frame not in by_frame)
            mortal += len(by_frame) < KEY_FRAMES
        # Through the scene: at the last frame every live flame's object shows its points.
        scn.frame_set(KEY_FRAMES)
        sp = flames_mod.read_spines(flames_mod.spines_path(folder, KEY_FRAMES))
        start = 0
        for fid, count in zip(sp["ids"], sp["counts"]):
            ob = bpy.data.objects[keys_mod.object_name(int(fid))]
            self.assertFalse(ob.hide_viewport)
            co = np.array([p.co[:3] for p in ob.data.splines[0].points])[:count]
            np.testing.assert_allclose(co, sp["points"][start:start + count], atol=1e-6)
            start += count
        print(f"  keyframes: {len(tracks)} flame ids, {mortal} not alive on every frame")
        self.assertGreater(mortal, 0)  # the hide keys are exercised

    def test_bad_input(self):
        folder = os.path.join(self.tmp, "bad")
        src = flame_scene(folder)
        scn = bpy.context.scene
        f = scn.plume_flames
        op = bpy.ops.plume.flames_bake

        def state():
            return (len(bpy.data.objects), len(bpy.data.volumes), len(bpy.data.curves),
                    len(bpy.data.lights), tuple(tree_listing(self.tmp)))
        f.points = 1
        assert_reports_error(self, op, r"Control Points \(n\) \(Physics Properties › Plume › "
                             r"Flames\) must be in \[2, 256\] \(got 1\)", state)
        f.points = 16
        f.height_persistent = f.height_intermittent
        assert_reports_error(self, op, r"Persistent Height \(H_p.*below Intermittent Height",
                             state)
        f.height_persistent = 0.03
        f.height_max = 0.01
        assert_reports_error(self, op, r"Max Height \(H_max.*Intermittent Height", state)
        f.height_max = 0.08
        # The noises (§4.2, §4.5): named with the paper's symbol and the core's range.
        f.spine_noise_scale = 0.0
        assert_reports_error(self, op, r"Spine Noise Scale \(Λ\) \(Physics Properties › Plume › "
                             r"Flames › Noise\) must be in \(0, 10000\] m \(got 0\)", state)
        f.spine_noise_scale = 0.25
        f.kolmogorov_drift = (0.0, 0.0, -5000.0)
        assert_reports_error(self, op, r"Kolmogorov Drift \(c\) \(Physics Properties › Plume › "
                             r"Flames › Noise\) must be in \[-1000, 1000\] m/s per axis "
                             r"\(got \(0\.0, 0\.0, -5000\.0\)\)", state)
        f.kolmogorov_drift = (0.0, 0.0, 0.5)
        f.flow_noise_frequency = -1.0
        assert_reports_error(self, op, r"Flow Noise Frequency \(ν\) \(Physics Properties › "
                             r"Plume › Flames › Noise\) must be in \[0, 1000\] Hz \(got -1\)",
                             state)
        f.flow_noise_frequency = 3.0
        src.plume.flame.profile = 'CUSTOM'
        assert_reports_error(self, op, r"'Candle'.*Profile Curve is empty", state)
        src.plume.flame.profile = 'CANDLE'
        img = bpy.data.images.new("Gone", 4, 4)
        img.source = 'FILE'
        img.filepath = os.path.join(self.tmp, "no_such_image.png")
        src.plume.flame.color_source = 'IMAGE'
        src.plume.flame.color_image = img
        assert_reports_error(self, op, r"'Candle'.*Colour Image 'Gone' cannot be read", state)
        src.plume.flame.color_image = None
        src.plume.flame.color_source = 'PROFILE'
        src.plume.role = 'NONE'
        assert_reports_error(self, op, r"no Flame Source: select a mesh and press "
                             r"Physics Properties › Plume › Flame Source", state)

    def test_noise_settings_reach_the_bake(self):
        """§4.2: the spine's Kolmogorov noise moves the candle's control points (off, eq. 1
        without it) and its scale Λ changes how; the same settings bake the same spines. §4.5:
        the render particles' Kolmogorov scale changes the VDB, not the spines."""
        from plume import flames as flames_mod
        frame = 6

        def bake(name, **settings):
            folder = os.path.join(self.tmp, name)
            flame_scene(folder)
            f = bpy.context.scene.plume_flames
            f.frame_end = frame
            for key, value in settings.items():
                setattr(f, key, value)
            self.assertEqual(bpy.ops.plume.flames_bake(), {'FINISHED'})
            sp = flames_mod.read_spines(flames_mod.spines_path(folder, frame))
            grid = native().read_vdb_grid(flames_mod.volume_path(folder, frame), "density")
            # The attached flame: the first (one source), n points.
            return sp["points"][:f.points], np.asarray(grid["values"])

        on, density = bake("noise_on")
        again, density_again = bake("noise_again")
        off, _ = bake("noise_off", spine_noise=0.0)
        scale, _ = bake("noise_scale", spine_noise_scale=0.05)
        same_spines, other_density = bake("render_scale", kolmogorov_scale=0.05)
        np.testing.assert_array_equal(on, again)
        np.testing.assert_array_equal(density, density_again)
        moved = float(np.abs(on - off).max())
        print(f"  candle, frame {frame}: spine noise moves a control point by up to "
              f"{moved * 1e3:.2f} mm; Λ = 0.05 m instead of 0.25 m by up to "
              f"{float(np.abs(on - scale).max()) * 1e3:.2f} mm")
        self.assertGreater(moved, 1e-4)
        self.assertGreater(float(np.abs(on - scale).max()), 1e-4)
        np.testing.assert_array_equal(on, same_spines)
        self.assertFalse(density.shape == other_density.shape
                         and np.array_equal(density, other_density))


if __name__ == "__main__":
    run(FlamesTest)
