"""Hand edits of streak surfaces ([Smoke Surfaces] §5, Figure 13), Bake to Keyframes and the
OpenSubdiv mesh export, on the Figure 1 setup of test_streak_surfaces.py (50³, 20 point sources).

An edit made on frame 10 is stored per control point (u, v index) as an offset in the sheet's
local frame there (tangent, binormal, normal at the control point's Greville abscissae) and
shows, moved and turned with the surface, on frame 1, the last frame and frame 200:
point = cache(frame) + R(frame) R(10)ᵀ move. A sheet turned by 90° between two frames carries
its edit turned by 90°; world-space edits of older files are migrated.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_surface_edits.py
"""

import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import (add_domain, compat, native, reset_scene, rmtree, run,  # noqa: E402
                     select_only, temp_dir)
from test_streak_surfaces import FRAMES, build_scene, counts, surface_objects  # noqa: E402

EDIT_FRAME = 10
MOVE = np.array([0.15, -0.05, 0.25], dtype=np.float32)
EDITS = "plume_surface_edits_local"


def points_of(ob, evaluated=False):
    if evaluated:
        ob = ob.evaluated_get(bpy.context.evaluated_depsgraph_get())
    pts = ob.data.splines[0].points
    co = np.empty(len(pts) * 4, np.float32)
    pts.foreach_get("co", co)
    return co.reshape(-1, 4)


def cache_points(ob):
    """The surface's control points per cached frame, read straight from its file."""
    with np.load(bpy.path.abspath(ob["plume_surface_cache"])) as z:
        return int(z["frame_start"]), np.array(z["control_points"])


def cache_at(ob, frame):
    start, cps = cache_points(ob)
    return cps[min(max(frame - start, 0), len(cps) - 1)]


def frames_at(ob, frame):
    """Local frames (n, 3, 3), rows tangent, binormal, normal, of the cached surface on `frame`,
    at the control points' Greville abscissae; a control point without one there takes the
    nearest cached frame's."""
    start, cps = cache_points(ob)
    sp = ob.data.splines[0]

    def at(i):
        s = {"control_points": cps[i], "nu": sp.point_count_u, "nv": sp.point_count_v,
             "order_u": sp.order_u, "order_v": sp.order_v}
        axes, valid = native().control_point_frames(s)
        return np.array(axes), np.asarray(valid, bool)

    i = min(max(frame - start, 0), len(cps) - 1)
    axes, valid = at(i)
    for step in range(1, len(cps)):
        for j in (i - step, i + step):
            if 0 <= j < len(cps) and not valid.all():
                other, ok = at(j)
                fill = ~valid & ok
                axes[fill], valid = other[fill], valid | fill
    return axes


def moved_by(ob, frame, edit_frame=EDIT_FRAME):
    """MOVE made on edit_frame, as it shows on `frame`: turned from that frame's local frames
    into this one's, float64 (len(edited_indices), 3)."""
    k = edited_indices(ob)
    local = np.einsum("nkj,j->nk", frames_at(ob, edit_frame)[k], MOVE.astype(np.float64))
    return np.einsum("nk,nkj->nj", local, frames_at(ob, frame)[k])


def edited_indices(ob):
    """A few control points in the middle of the net (u, v index space)."""
    sp = ob.data.splines[0]
    nu, nv = sp.point_count_u, sp.point_count_v
    v = nv // 2
    return [v * nu + u for u in range(nu // 3, nu // 3 + 4)]


class SurfaceEditsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        reset_scene()
        cls.tmp = temp_dir("plume_edits_")
        cls.dom = build_scene(os.path.join(cls.tmp, "cache"))
        assert bpy.ops.plume.bake() == {'FINISHED'}
        assert bpy.ops.plume.surfaces_build() == {'FINISHED'}
        # Two or more sheets, so edits of one are seen not to touch the others.
        from plume.operators.surfaces import cached_distances
        groups = cached_distances(cls.dom)
        h = np.concatenate([g.h.pairs()[2] for g in groups.values()])  # every h below the mean
        cls.dom.plume.domain.streak_threshold = float(np.percentile(h, 10))
        assert bpy.ops.plume.surfaces_build() == {'FINISHED'}

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def setUp(self):
        select_only(bpy.data.objects["Domain"])
        bpy.context.scene.frame_set(1)
        self.obs = sorted(surface_objects(), key=lambda o: o.name)
        self.assertGreaterEqual(len(self.obs), 1)

    def edit_on_frame(self, ob, frame=EDIT_FRAME):
        """The artist's move by script (spline.points[i].co) on `frame`."""
        bpy.context.scene.frame_set(frame)
        sp = ob.data.splines[0]
        for k in edited_indices(ob):
            x, y, z, w = sp.points[k].co
            sp.points[k].co = (x + MOVE[0], y + MOVE[1], z + MOVE[2], w)
        return points_of(ob)

    def assert_follows(self, ob, frame, moved=True, evaluated=False):
        bpy.context.scene.frame_set(frame)
        want = cache_at(ob, frame).copy()
        if moved:
            want[edited_indices(ob), :3] += moved_by(ob, frame)
        np.testing.assert_allclose(points_of(ob, evaluated), want, atol=1e-5,
                                   err_msg=f"{ob.name} on frame {frame}")

    def test_0_a_sheet_shows_its_own_panel(self):
        # Selecting a sheet shows how hand edits work and its buttons, in Properties › Object
        # Data and in the viewport's sidebar; the domain does not get them.
        from test_roles_ui import draw_panel
        ob = self.obs[0]
        for name in ("DATA_PT_plume_sheet", "VIEW3D_PT_plume_sheet"):
            cls = getattr(bpy.types, name)
            log = draw_panel(self, cls, ob)
            self.assertIsNotNone(log, f"{name} on a sheet")
            ops = {n for kind, n in log if kind == "operator"}
            self.assertLessEqual({"plume.surface_edits_store", "plume.surface_edits_clear",
                                  "plume.surfaces_bake_keyframes",
                                  "plume.surfaces_export_mesh"}, ops)
            labels = " ".join(n for kind, n in log if kind == "label")
            self.assertIn("Tab into Edit Mode", labels)
            self.assertIn("Changing frame after Edit Mode stores them", labels)
            self.assertIsNone(draw_panel(self, cls, bpy.data.objects["Domain"]))

    def test_1_edit_moves_with_surface(self):
        ob, others = self.obs[0], self.obs[1:]
        edited = self.edit_on_frame(ob)
        for f in (1, FRAMES, 200):  # captured by the handler on the first frame change
            self.assert_follows(ob, f)
        off = np.asarray(ob[EDITS]).reshape(-1, 3)
        self.assertEqual(off.shape[0], len(ob.data.splines[0].points))
        local = np.einsum("nkj,j->nk", frames_at(ob, EDIT_FRAME)[edited_indices(ob)], MOVE)
        np.testing.assert_allclose(off[edited_indices(ob)], local, atol=1e-5)
        np.testing.assert_allclose(np.linalg.norm(local, axis=1), np.linalg.norm(MOVE), rtol=1e-5)
        mask = np.ones(len(off), bool)
        mask[edited_indices(ob)] = False
        self.assertEqual(np.abs(off[mask]).max(), 0.0)
        # Back on frame 10 the edited net is exactly what the artist left.
        bpy.context.scene.frame_set(EDIT_FRAME)
        np.testing.assert_allclose(points_of(ob), edited, atol=1e-5)
        # The surface moved between frames 1 and the last, so did the edited points, and the
        # sheet turned there: so did the offsets.
        self.assertGreater(np.abs(cache_at(ob, 1) - cache_at(ob, FRAMES)).max(), 0.05)
        turned = np.abs(moved_by(ob, FRAMES) - MOVE).max()
        print(f"  edit offset turned with the sheet by up to {turned:.3f} (|move| = "
              f"{np.linalg.norm(MOVE):.3f}) between frames {EDIT_FRAME} and {FRAMES}")
        self.assertGreater(turned, 1e-3)
        for o in others:  # the other sheets follow the plain cache
            self.assertNotIn(EDITS, o)
            self.assert_follows(o, FRAMES, moved=False)
        # Clear Edits (domain active: all its surfaces) puts the cache back.
        self.assertEqual(bpy.ops.plume.surface_edits_clear(), {'FINISHED'})
        self.assertNotIn(EDITS, ob)
        np.testing.assert_allclose(points_of(ob), cache_at(ob, bpy.context.scene.frame_current),
                                   atol=0)
        for f in (1, FRAMES):
            self.assert_follows(ob, f, moved=False)

    def test_2_store_operator_from_edit_mode(self):
        ob = self.obs[-1]
        bpy.context.scene.frame_set(EDIT_FRAME)
        select_only(ob)
        bpy.ops.object.mode_set(mode='EDIT')
        try:
            sp = ob.data.splines[0]  # the edit-mode net
            for k in edited_indices(ob):
                x, y, z, w = sp.points[k].co
                sp.points[k].co = (x + MOVE[0], y + MOVE[1], z + MOVE[2], w)
            self.assertEqual(bpy.ops.plume.surface_edits_store(), {'FINISHED'})
        finally:
            bpy.ops.object.mode_set(mode='OBJECT')
        self.assertIn(EDITS, ob)
        for f in (1, FRAMES, 200):
            self.assert_follows(ob, f)
        select_only(ob)
        self.assertEqual(bpy.ops.plume.surface_edits_clear(), {'FINISHED'})
        self.assert_follows(ob, 5, moved=False)

    def test_3_store_operator_by_script(self):
        ob = self.obs[0]
        self.edit_on_frame(ob)
        select_only(ob)
        self.assertEqual(bpy.ops.plume.surface_edits_store(), {'FINISHED'})
        np.testing.assert_allclose(np.asarray(ob[EDITS]).reshape(-1, 3)[edited_indices(ob)],
                                   np.einsum("nkj,j->nk", frames_at(ob, EDIT_FRAME)[
                                       edited_indices(ob)], MOVE), atol=1e-5)
        self.assert_follows(ob, 1)
        self.assertEqual(bpy.ops.plume.surface_edits_clear(), {'FINISHED'})

    def test_4_export_mesh(self):
        from plume.build.surface_mesh import expected_vertex_count
        scn = bpy.context.scene
        scn.frame_set(FRAMES // 2)
        self.assertEqual(bpy.ops.plume.surfaces_export_mesh(), {'FINISHED'})
        for level, obs in ((2, self.obs), (1, self.obs[:1])):
            if level != 2:
                select_only(obs[0])
                self.assertEqual(bpy.ops.plume.surfaces_export_mesh(level=level), {'FINISHED'})
            for ob in obs:
                m = bpy.data.objects.get(f"{ob.name}_mesh")
                self.assertIsNotNone(m, ob.name)
                self.assertEqual(m.type, 'MESH')
                sp = ob.data.splines[0]
                nu, nv = sp.point_count_u, sp.point_count_v
                self.assertEqual(len(m.data.vertices), expected_vertex_count(nu, nv, level))
                self.assertEqual(len(m.data.polygons), (nu - 1) * (nv - 1) * 4 ** level)
                attr = m.data.attributes.get("density")
                self.assertIsNotNone(attr)
                self.assertEqual((attr.domain, attr.data_type), ('POINT', 'FLOAT'))
                d = np.empty(len(m.data.vertices), np.float32)
                attr.data.foreach_get("value", d)
                self.assertGreaterEqual(d.min(), 0.0)
                self.assertLessEqual(d.max(), 1.0)
                self.assertGreater(d.max(), 0.0, "no density on the exported mesh")
                # Limit surface inside the control net's bounding box (convex hull property).
                v = np.empty(len(m.data.vertices) * 3, np.float32)
                m.data.vertices.foreach_get("co", v)
                v = v.reshape(-1, 3)
                c = points_of(ob)[:, :3]
                self.assertTrue(np.all(v >= c.min(0) - 1e-4) and np.all(v <= c.max(0) + 1e-4))
                self.assertEqual(set(m.users_collection), set(ob.users_collection))
        n = len(bpy.data.meshes)
        select_only(bpy.data.objects["Domain"])
        self.assertEqual(bpy.ops.plume.surfaces_export_mesh(), {'FINISHED'})  # replaces
        self.assertEqual(len(bpy.data.meshes), n)

    def test_5_bake_keyframes(self):
        ob = self.obs[0]
        self.edit_on_frame(ob)
        select_only(bpy.data.objects["Domain"])
        self.assertEqual(bpy.ops.plume.surfaces_bake_keyframes(), {'FINISHED'})
        start, cps = cache_points(ob)
        for o in self.obs:
            self.assertTrue(o.get("plume_surface_baked"))
            fcs = compat.fcurves(o.data)
            self.assertEqual(len(fcs), len(o.data.splines[0].points) * 3)
            self.assertEqual({len(fc.keyframe_points) for fc in fcs}, {len(cps)})
        # Without the handler, the F-curves alone give cache + offsets.
        from plume.build import surfaces as build
        handlers = bpy.app.handlers.frame_change_pre
        handlers.remove(build.frame_change_pre)
        try:
            for f in (3, FRAMES - 5):
                self.assert_follows(ob, f, evaluated=True)
                for o in self.obs[1:]:
                    self.assert_follows(o, f, moved=False, evaluated=True)
        finally:
            handlers.append(build.frame_change_pre)
        bpy.context.scene.frame_set(7)
        self.assertEqual(build.last_update_seconds, [])  # baked surfaces are not rewritten
        # Store on a baked surface: a clear error.
        with self.assertRaises(RuntimeError) as ctx:
            bpy.ops.plume.surface_edits_store()
        self.assertIn("baked to keyframes", str(ctx.exception))

    def test_6_errors(self):
        for op, name in ((bpy.ops.plume.surface_edits_store, "store"),
                         (bpy.ops.plume.surfaces_bake_keyframes, "bake"),
                         (bpy.ops.plume.surfaces_export_mesh, "export")):
            select_only(bpy.data.objects["Incense"])
            before = counts()
            with self.assertRaises(RuntimeError) as ctx:
                op()
            self.assertRegex(str(ctx.exception), r"'Incense' is not a Plume streak surface", name)
            self.assertEqual(counts(), before)
        other = add_domain(name="Empty Domain", location=(5.0, 0.0, 1.0))
        select_only(other)
        before = counts()
        for op in (bpy.ops.plume.surface_edits_clear, bpy.ops.plume.surfaces_export_mesh):
            with self.assertRaises(RuntimeError) as ctx:
                op()
            self.assertIn("has no streak surfaces: build them first (Physics Properties › Plume › "
                          "Streak Surfaces › Build Surfaces)", str(ctx.exception))
        self.assertEqual(counts(), before)
        bpy.data.objects.remove(other, do_unlink=True)


class SheetTurnTest(unittest.TestCase):
    """A flat sheet that turns 90° about z between frames 1 and 2 (a cache written by hand):
    an edit made on frame 1 shows turned by 90° on frame 2; a world-space edit of an older file
    is migrated so that the frame it was made on is unchanged and it turns from there."""

    NU, NV = 6, 4
    TURN = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # 90° about z
    K = 2 * 6 + 3  # control point (u, v) = (3, 2), inside the net

    def setUp(self):
        reset_scene()
        bpy.context.view_layer.update()  # drop the removed default objects from the view layer
        self.tmp = temp_dir("plume_turn_")
        from plume.build import surfaces as build
        u, v = np.meshgrid(np.linspace(0.2, 0.7, self.NU), np.linspace(0.1, 0.4, self.NV))
        flat = np.stack([u, np.zeros_like(u), v, np.ones_like(u)], -1).reshape(-1, 4)
        turned = flat.copy()
        turned[:, :3] = flat[:, :3] @ self.TURN.T
        self.cps = np.stack([flat, turned]).astype(np.float32)
        path = os.path.join(self.tmp, "surface_0.npz")
        np.savez(path, control_points=self.cps, frame_start=1, nu=self.NU, nv=self.NV,
                 order_u=4, order_v=4)
        scn = bpy.context.scene
        self.ob = build.surface_object("Turning", scn.collection, self.NU, self.NV,
                                       bpy.context.view_layer)
        sp = self.ob.data.splines[0]
        sp.order_u = sp.order_v = 4
        sp.use_endpoint_u = sp.use_endpoint_v = True
        self.ob[build.CACHE_KEY] = path
        scn.frame_set(1)

    def tearDown(self):
        rmtree(self.tmp)

    def test_edit_turns_with_the_sheet(self):
        sp = self.ob.data.splines[0]
        np.testing.assert_allclose(points_of(self.ob), self.cps[0], atol=1e-6)
        x, y, z, w = sp.points[self.K].co
        sp.points[self.K].co = (x + MOVE[0], y + MOVE[1], z + MOVE[2], w)
        bpy.context.scene.frame_set(2)
        got = points_of(self.ob)[self.K, :3] - self.cps[1][self.K, :3]
        np.testing.assert_allclose(got, self.TURN @ MOVE, atol=1e-5)
        others = np.arange(self.NU * self.NV) != self.K
        np.testing.assert_allclose(points_of(self.ob)[others], self.cps[1][others], atol=1e-6)
        bpy.context.scene.frame_set(1)  # and back: the edit where it was made
        np.testing.assert_allclose(points_of(self.ob)[self.K, :3] - self.cps[0][self.K, :3], MOVE,
                                   atol=1e-5)

    def test_motion_blur_subframes_blend_the_frames(self):
        """Between frames (Cycles' motion blur sets the scene at sub-frames of its shutter) the
        sheet is the blend of the two cached frames around it, with its edit turned along, and
        writing it there is not taken for a hand edit."""
        scn = bpy.context.scene
        scn.frame_set(1, subframe=0.25)
        np.testing.assert_allclose(points_of(self.ob), 0.75 * self.cps[0] + 0.25 * self.cps[1],
                                   atol=1e-6)
        scn.frame_set(2)
        self.assertNotIn(EDITS, self.ob)  # the blended points were not captured as an edit
        np.testing.assert_allclose(points_of(self.ob), self.cps[1], atol=1e-6)
        scn.frame_set(1)
        sp = self.ob.data.splines[0]
        x, y, z, w = sp.points[self.K].co
        sp.points[self.K].co = (x + MOVE[0], y + MOVE[1], z + MOVE[2], w)
        scn.frame_set(1, subframe=0.5)
        want = 0.5 * self.cps[0] + 0.5 * self.cps[1]
        want[self.K, :3] += 0.5 * MOVE + 0.5 * (self.TURN @ MOVE)
        np.testing.assert_allclose(points_of(self.ob), want, atol=1e-5)
        scn.frame_set(1)  # back on the frame: the edit once, not folded in twice
        np.testing.assert_allclose(points_of(self.ob)[self.K, :3] - self.cps[0][self.K, :3], MOVE,
                                   atol=1e-5)
        scn.frame_set(5, subframe=0.5)  # past the cache: its last frame, unblended
        want = self.cps[1].copy()
        want[self.K, :3] += self.TURN @ MOVE
        np.testing.assert_allclose(points_of(self.ob), want, atol=1e-5)

    def test_world_space_edits_of_older_files_are_migrated(self):
        world = np.zeros((self.NU * self.NV, 3))
        world[self.K] = MOVE
        # What older versions stored and wrote: world offsets, points = cache + offsets.
        self.ob["plume_surface_edits"] = world.ravel()
        self.ob["plume_surface_frame"] = 0
        sp = self.ob.data.splines[0]
        x, y, z, w = sp.points[self.K].co
        sp.points[self.K].co = (x + MOVE[0], y + MOVE[1], z + MOVE[2], w)
        bpy.context.scene.frame_set(2)
        self.assertNotIn("plume_surface_edits", self.ob)
        self.assertIn(EDITS, self.ob)
        got = points_of(self.ob)[self.K, :3] - self.cps[1][self.K, :3]
        np.testing.assert_allclose(got, self.TURN @ MOVE, atol=1e-5)
        bpy.context.scene.frame_set(1)
        np.testing.assert_allclose(points_of(self.ob)[self.K, :3] - self.cps[0][self.K, :3], MOVE,
                                   atol=1e-5)


if __name__ == "__main__":
    run(SurfaceEditsTest, SheetTurnTest)
