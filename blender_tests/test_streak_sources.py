"""Streakline point sources ([Smoke Surfaces] §3.2-3.3) through the operators: the vertices of
a picked mesh as point sources, a source split into candidate groups, a traced bake resumed
from the tracers' checkpoint bit for bit, and Figure 10's keyed source (density 0 and particle
emission off for some frames). Bad values give clear errors and change nothing.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_streak_sources.py
"""

import json
import os
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import (add_domain, compat, add_sphere_source, assert_reports_error, native,  # noqa: E402
                     reset_scene, rmtree, run, select_only, temp_dir)

#: 16 cells along 2 units: a bake of a few frames takes well under a second.
RESOLUTION = 16
#: Float32 rounding of world positions about 1 unit from the origin (2^-23 ≈ 1.2e-7 relative),
#: with margin for the matrix product done in float64 here and there.
POSITION_TOLERANCE = 1e-6


def build_scene(cache_dir, frame_end=3, point_sources=4, split=1):
    """A 2-unit cube domain over z in [0, 2] with a small sphere source low in it, streaks on."""
    src = add_sphere_source(radius=0.2, location=(0.0, 0.0, 0.35))
    s = src.plume.source
    s.point_placement = 'CELLS'
    s.point_sources = point_sources
    s.candidate_split = split
    s.velocity = (0.0, 0.0, 0.5)
    dom = add_domain(resolution=RESOLUTION, frame_end=frame_end, cache_directory=cache_dir + "/")
    dom.plume.domain.streaks = True
    select_only(dom)
    return dom, src


def add_point_mesh(verts, name="Dots"):
    """A mesh object of loose vertices (no faces), as an artist would place emission points."""
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(v) for v in verts], [], [])
    ob = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def streaks(folder, frame):
    return native().read_streak_file(os.path.join(folder, f"streaks_{frame:04d}.bin"))


def source_positions(snap):
    """Where each streakline's youngest particle is: at its point source (emission every step)."""
    ends = np.cumsum(np.asarray(snap["counts"], dtype=np.int64)) - 1
    return np.asarray(snap["positions"], dtype=np.float64)[ends]


def manifest(folder):
    with open(os.path.join(folder, "manifest.json")) as f:
        return json.load(f)


def key_source(src, keys):
    """CONSTANT keys (frame, on) on the source's density (1 or 0) and emit_particles, as in
    Figure 10, written as F-curves of a new action (examples/streak_surfaces/sphere_collision.py
    keys them with
    keyframe_insert)."""
    action = bpy.data.actions.new("SourceKeys")
    src.animation_data_create().action = action
    for path in ("plume.source.density", "plume.source.emit_particles"):
        fcurve = compat.fcurve_new(src, path)
        for frame, on in keys:
            fcurve.keyframe_points.insert(frame, float(on)).interpolation = 'CONSTANT'


def source_cells_ijk(dom):
    """(i, j, k) of the cells the bake's Source fills (native.source_cells on its snapshot)."""
    from plume.native_params import to_native_params
    from plume.snapshot import take_snapshot
    nat = native()
    select_only(dom)
    snap = take_snapshot(bpy.context)
    e = next(e for e in snap.emitters if e.role == "SOURCE")
    params = to_native_params(snap.solver, nat)
    cells, _ = nat.source_cells(e.vertices, e.triangles, e.matrix_at(0), e.matrix_at(1), params,
                                e.name)
    nx, ny, _nz = params.resolution
    cells = np.asarray(cells, dtype=np.int64)
    return np.stack([cells % nx, (cells // nx) % ny, cells // (nx * ny)], axis=1)


def vdb_at(folder, frame, cells):
    """The VDB density of a frame at cells (i, j, k) (0 outside the stored box)."""
    g = native().read_vdb_grid(os.path.join(folder, f"volume_{frame:04d}.vdb"), "density")
    values, lo = g["values"], np.asarray(g["min"])
    q = cells - lo
    inside = np.all((q >= 0) & (q < values.shape), axis=1)
    out = np.zeros(len(cells))
    out[inside] = values[tuple(q[inside].T)]
    return out


def counts():
    return (len(bpy.data.objects), len(bpy.data.meshes), len(bpy.data.volumes),
            len(bpy.data.curves))


#: Where the Source panel is, as the messages name it
AT = r"\(Physics Properties › Plume › Source\)"


class StreakSourcesTest(unittest.TestCase):
    def setUp(self):
        reset_scene()
        self.tmp = temp_dir("plume_streak_sources_")
        self.cache = os.path.join(self.tmp, "cache")
        self.folder = os.path.join(self.cache, "Domain")

    def tearDown(self):
        rmtree(self.tmp)

    def assert_bake_error(self, pattern):
        """The bake fails with a message matching `pattern` and leaves no file and no datablock."""
        assert_reports_error(self, bpy.ops.plume.bake, pattern, counts)
        self.assertFalse(os.path.exists(self.cache), os.listdir(self.tmp))

    # ------------------------------------------------------------------ vertex point sources
    def test_vertex_sources_one_streakline_per_vertex_at_frame_start(self):
        dom, src = build_scene(self.cache)
        dots = add_point_mesh([(x, 0.0, 0.0) for x in (-0.2, -0.1, 0.0, 0.1, 0.2)])
        dots.scale = (1.5, 1.0, 1.0)
        # Animated: the vertices count where the mesh is at frame_start (1), not the current frame.
        scn = bpy.context.scene
        for frame, loc in ((1, (0.0, 0.1, 0.5)), (5, (0.0, 0.3, 0.9))):
            dots.location = loc
            dots.keyframe_insert("location", frame=frame)
        # Evaluated mesh: the modifier's copies are point sources too.
        array = dots.modifiers.new("Array", 'ARRAY')
        array.count, array.use_relative_offset = 2, False
        array.use_constant_offset, array.constant_offset_displace = True, (0.0, 0.0, 0.2)
        scn.frame_set(1)
        dg = bpy.context.evaluated_depsgraph_get()
        ev = dots.evaluated_get(dg)
        m = np.array(ev.matrix_world, dtype=np.float64)
        local = np.array([tuple(v.co) for v in ev.to_mesh().vertices], dtype=np.float64)
        ev.to_mesh_clear()
        expected = local @ m[:3, :3].T + m[:3, 3]
        self.assertEqual(len(expected), 10)
        scn.frame_set(5)
        src.plume.source.point_source_mesh = dots
        select_only(dom)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        self.assertEqual(scn.frame_current, 5)
        for frame in (1, 3):
            snap = streaks(self.folder, frame)
            self.assertEqual(len(snap["counts"]), 10, frame)  # one streakline per vertex
            np.testing.assert_allclose(source_positions(snap), expected, rtol=0,
                                       atol=POSITION_TOLERANCE)
            self.assertEqual(set(snap["groups"].tolist()), {0})
        # The vertices are part of the bake's settings: moving the mesh starts over.
        dots.animation_data_clear()
        dots.location = (0.0, 0.1, 0.6)
        dom.plume.domain.frame_end = 4
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        self.assertFalse(manifest(self.folder)["last_run"]["resumed"])
        snap = streaks(self.folder, 1)
        self.assertAlmostEqual(float(source_positions(snap)[:, 2].min()), 0.6, places=5)

    def test_bad_point_source_meshes_change_nothing(self):
        dom, src = build_scene(self.cache)
        dots = add_point_mesh([(0.0, 0.0, 0.5), (0.5, 0.0, 0.5), (3.0, 0.0, 0.5)])
        src.plume.source.point_source_mesh = dots
        select_only(dom)
        self.assert_bake_error(r"source 'Source': 1 of the 3 vertices of its Point Source Mesh "
                               r"'Dots' lie outside domain 'Domain' .*vertex 2 at \(3, 0, 0\.5\)")
        src.plume.source.point_source_mesh = add_point_mesh([], name="Empty")
        self.assert_bake_error(rf"source 'Source': Point Source Mesh {AT} 'Empty' has no vertices")
        # A script can bypass the property's poll; the bake still refuses a non-mesh.
        curve = bpy.data.objects.new("Path", bpy.data.curves.new("Path", 'CURVE'))
        bpy.context.scene.collection.objects.link(curve)
        try:
            src.plume.source.point_source_mesh = curve
        except (TypeError, ValueError, RuntimeError):
            pass
        else:
            self.assert_bake_error(rf"Point Source Mesh {AT} 'Path' must be a mesh object")
        # Two vertices cannot make two groups of two.
        src.plume.source.point_source_mesh = add_point_mesh([(0, 0, 0.5), (0.1, 0, 0.5)], "Two")
        src.plume.source.candidate_split = 2
        self.assert_bake_error(rf"source 'Source': Split Into Groups {AT} 2 needs "
                               r"at least 4 point sources .*it has 2.*lower Split Into Groups")

    # ------------------------------------------------------------------ split into groups
    def test_split_groups_pure(self):
        from plume.point_sources import split_groups
        from plume.settings import EmitterSnapshot, candidate_groups
        # Longest extent along y; equal y values keep their index order; 7 into 3: sizes 3, 2, 2.
        pts = np.array([[0, 5, 0], [0, 1, 0], [0, 3, 0], [0.5, 1, 0], [0, 0, 0], [0, 6, 1],
                        [0, 3, 0]], dtype=np.float32)
        g = split_groups(pts, 10, 3)
        self.assertEqual(g.tolist(), [12, 10, 11, 10, 10, 12, 11])
        self.assertEqual(split_groups(pts, 4, 1).tolist(), [4] * 7)
        # Groups of a split source come after every other group, in source order.
        def src(name, group=-1, split=1):
            return EmitterSnapshot(name=name, role="SOURCE", vertices=np.zeros((0, 3)),
                                   triangles=np.zeros((0, 3)), matrices=[np.eye(4)],
                                   candidate_group=group, candidate_split=split)
        self.assertEqual(candidate_groups([src("A"), src("B", 0, 2), src("C", 5), src("D")]),
                         [0, 6, 5, 1])

    def test_split_source_gives_groups_never_in_one_surface(self):
        from plume import streak_surfaces as ss
        from plume.point_sources import split_groups
        dom, src = build_scene(self.cache, frame_end=4, split=2)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        snap = streaks(self.folder, 4)
        groups = np.asarray(snap["groups"])
        n = len(groups)
        self.assertGreaterEqual(n, 8)
        self.assertEqual(sorted(set(groups.tolist())), [0, 1])  # the only source: from 0 on
        self.assertEqual(np.count_nonzero(groups == 0), n // 2)
        # The groups are the two halves along the axis of largest extent.
        at = source_positions(snap)
        self.assertEqual(groups.tolist(), split_groups(at.astype(np.float32), 0, 2).tolist())
        axis = int(np.argmax(at.max(axis=0) - at.min(axis=0)))
        self.assertLessEqual(at[groups == 0, axis].max(), at[groups == 1, axis].min())
        # A threshold joining everything: one surface per group, never one across both.
        nat = native()
        frames = ss.load_frames(nat, self.folder, 1, 4)
        h0 = 1e6
        everything = nat.cluster_sources(nat.streak_distances(frames, np.arange(n), reach=h0), h0)
        self.assertEqual(len(everything), 1)  # unsplit, all would share one surface
        plans = ss.plan_surfaces(nat, ss.group_distances(nat, frames), h0)
        self.assertEqual(len(plans), 2)
        for plan in plans:
            self.assertEqual(set(groups[plan.sources].tolist()), {plan.group})
        dom.plume.domain.streak_threshold = h0
        self.assertEqual(bpy.ops.plume.surfaces_build(), {'FINISHED'})
        self.assertEqual(len([o for o in bpy.data.objects if o.type == 'SURFACE']), 2)

    def test_bad_split_changes_nothing(self):
        dom, src = build_scene(self.cache)
        for value in (0, 65, -1):
            src.plume.source.candidate_split = value
            self.assert_bake_error(rf"source 'Source': Split Into Groups {AT} must be "
                                   r"in \[1, 64\] "
                                   rf"candidate groups \(got {value}\)")
        src.plume.source.candidate_split = 64
        src.plume.source.point_placement = 'CELLS'
        src.plume.source.point_sources = 1
        self.assert_bake_error(rf"Split Into Groups {AT} 64 needs at least 128 "
                               r"point sources")

    def test_hand_groups_from_vertex_groups(self):
        """§3.3 manual grouping (Figure 3(b)): the vertex groups of a point source mesh are
        candidate groups; with h0 joining everything each one is exactly one surface."""
        dom, src = build_scene(self.cache, frame_end=4)
        ring = [(0.15 * np.cos(a), 0.15 * np.sin(a), 0.5)
                for a in np.linspace(0.0, 2 * np.pi, 12, endpoint=False)]
        dots = add_point_mesh(ring, "Ring")
        for name, members in (("Left", range(0, 5)), ("Right", range(5, 6))):
            dots.vertex_groups.new(name=name).add(list(members), 1.0, 'REPLACE')
        src.plume.source.point_source_mesh = dots
        select_only(dom)
        # A hand group of one vertex cannot make a surface: refused, named, nothing written.
        self.assert_bake_error(rf"Point Source Mesh {AT} 'Ring': vertex group "
                               r"'Right' holds 1 vertex; a "
                               r"hand-made candidate group needs at least 2")
        dots.vertex_groups["Right"].add([6, 7, 8], 1.0, 'REPLACE')
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        groups = np.asarray(streaks(self.folder, 4)["groups"])
        # Vertex-group order, the vertices in none last.
        self.assertEqual(groups.tolist(), [0] * 5 + [1] * 4 + [2] * 3)
        dom.plume.domain.streak_threshold = 1e6  # no clustering inside a group
        self.assertEqual(bpy.ops.plume.surfaces_build(), {'FINISHED'})
        surfaces = [o for o in bpy.data.objects if o.type == 'SURFACE']
        self.assertEqual(len(surfaces), 3)
        from plume import _native
        from plume import streak_surfaces as ss
        from plume.operators.surfaces import compute_distances  # the build's h, in Blender
        plans = ss.plan_surfaces(_native, compute_distances(dom)[3], 1e6)
        self.assertEqual(sorted(len(p.sources) for p in plans), [3, 4, 5])
        # The least-squares net has at most one control point per streakline across.
        for o, p in zip(sorted(surfaces, key=lambda o: o.name), plans):
            self.assertLessEqual(o.data.splines[0].point_count_v, len(p.sources))

    # ------------------------------------------------------------------ resume
    def test_resumed_traced_bake_matches_straight_bake(self):
        resumed, straight = os.path.join(self.tmp, "resumed"), os.path.join(self.tmp, "straight")
        folder = os.path.join(resumed, "Domain")
        # Interrupted bake: frames 1..3 done. The last frame always gets its checkpoints, whatever
        # CHECKPOINT_COST_RATIO decides for the others.
        dom, _src = build_scene(resumed, frame_end=3)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        m = manifest(folder)
        self.assertEqual((m["last_complete_frame"], m["state_frame"]), (3, 3))
        self.assertTrue(os.path.isfile(os.path.join(folder, "tracer_state.bin")))
        mtimes = {f: os.stat(os.path.join(folder, f"streaks_{f:04d}.bin")).st_mtime_ns
                  for f in (1, 2, 3)}
        time.sleep(0.05)
        dom.plume.domain.frame_end = 7
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        m = manifest(folder)
        self.assertTrue(m["last_run"]["resumed"])
        self.assertEqual(m["last_run"]["computed_frames"], [4, 5, 6, 7])
        for f, t in mtimes.items():
            self.assertEqual(os.stat(os.path.join(folder, f"streaks_{f:04d}.bin")).st_mtime_ns, t)

        dom.plume.domain.cache_directory = straight + "/"
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        self.assertEqual(manifest(os.path.join(straight, "Domain"))["last_run"]["computed_frames"],
                         list(range(1, 8)))
        for f in range(1, 8):
            name = f"streaks_{f:04d}.bin"
            with open(os.path.join(folder, name), "rb") as a, \
                    open(os.path.join(straight, "Domain", name), "rb") as b:
                self.assertEqual(a.read(), b.read(), f"{name}: resumed bake differs")

    # ------------------------------------------------------------------ Figure 10: keyed source
    def test_keyed_density_and_emission_leave_a_gap(self):
        # Figure 10: density 0 and particle emission off for a stretch of frames (here 4-6).
        dom, src = build_scene(self.cache, frame_end=8)
        s = src.plume.source
        # 3 m/s carries the smoke out of the source cells within the 3 frames the source is off.
        s.velocity = (0.0, 0.0, 3.0)
        key_source(src, ((1, True), (4, False), (7, True)))
        select_only(dom)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        rows = {f: int(streaks(self.folder, f)["counts"][0]) for f in range(1, 9)}
        # Emission pauses while the only source is off and grows again after (one row per step).
        grew = {f: rows[f] - rows[f - 1] for f in range(2, 9)}
        self.assertEqual([grew[f] for f in (4, 5, 6)], [0, 0, 0], rows)
        for f in (2, 3, 7, 8):
            self.assertGreater(grew[f], 0, rows)
        # The source cells: smoke while on; none left after three frames off. Sources keep their
        # cells at max(ρ, ρ_source), so ρ_source = 0 adds nothing, the air flowing in from below
        # is clean and the mass correction scales values in proportion to them (0 stays 0):
        # exactly 0, up to float noise.
        cells = source_cells_ijk(dom)
        self.assertGreater(max(vdb_at(self.folder, 3, cells)), 0.5)
        self.assertLessEqual(max(vdb_at(self.folder, 6, cells)), 1e-6)
        self.assertGreater(max(vdb_at(self.folder, 7, cells)), 0.5)
        # The keys are per-frame inputs, not settings: the settings dict is as for an un-keyed
        # source (the values at frame_start, emit_particles on is not stored).
        m = manifest(self.folder)
        self.assertNotIn("emit_particles", m["settings"]["emitters"][0]["source"])
        self.assertEqual(m["settings"]["emitters"][0]["source"]["density"], 1.0)

        # Same keys, longer range: the bake resumes.
        dom.plume.domain.frame_end = 9
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        self.assertEqual(manifest(self.folder)["last_run"]["computed_frames"], [9])
        # A changed key makes the stored frames stale: the bake starts over.
        fcurve = compat.fcurves(src).find("plume.source.density")
        next(k for k in fcurve.keyframe_points if k.co.x == 7).co.y = 0.5
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        m = manifest(self.folder)
        self.assertFalse(m["last_run"]["resumed"])
        self.assertEqual(m["last_run"]["computed_frames"], list(range(1, 10)))
        # The new key's density, 0.5, give or take the few % the global mass correction adds.
        self.assertAlmostEqual(max(vdb_at(self.folder, 7, cells)), 0.5, delta=0.05)
        # So does a changed emission key alone (it changes only the particles).
        fcurve = compat.fcurves(src).find("plume.source.emit_particles")
        next(k for k in fcurve.keyframe_points if k.co.x == 7).co.y = 0.0
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        self.assertEqual(manifest(self.folder)["last_run"]["computed_frames"], list(range(1, 10)))
        self.assertEqual(int(streaks(self.folder, 9)["counts"][0]), rows[3])

    def test_bad_keyed_value_names_its_frame_and_changes_nothing(self):
        dom, src = build_scene(self.cache, frame_end=4)
        key_source(src, ((1, True), (3, False)))
        fcurve = compat.fcurves(src).find("plume.source.density")
        fcurve.keyframe_points[1].co.y = -1.0
        select_only(dom)
        self.assert_bake_error(rf"source 'Source': Density {AT} must be >= 0 "
                               r"\(got -1\.0 at frame 3\)")

    def test_bad_tracer_checkpoint_starts_over(self):
        dom, _src = build_scene(self.cache, frame_end=2)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        reference = streaks(self.folder, 2)
        path = os.path.join(self.folder, "tracer_state.bin")
        with open(path, "r+b") as f:  # one flipped bit: the checksum refuses the file
            f.seek(100)
            byte = f.read(1)
            f.seek(100)
            f.write(bytes([byte[0] ^ 0x01]))
        dom.plume.domain.frame_end = 4
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        m = manifest(self.folder)
        self.assertFalse(m["last_run"]["resumed"])
        self.assertEqual(m["last_run"]["computed_frames"], [1, 2, 3, 4])
        again = streaks(self.folder, 2)
        self.assertTrue(np.array_equal(again["positions"], reference["positions"]))
        # Without the tracers' checkpoint there is nothing to resume from either.
        os.remove(path)
        dom.plume.domain.frame_end = 5
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        self.assertEqual(manifest(self.folder)["last_run"]["computed_frames"], [1, 2, 3, 4, 5])


if __name__ == "__main__":
    run(StreakSourcesTest)
