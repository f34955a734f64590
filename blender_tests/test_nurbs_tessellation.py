"""The surface Blender tessellates is the core's surface ([Smoke Surfaces] §3.3).

For 2, 3, 5 and 11 streaklines of 1, 2, 3, 4 and 7 particles, with endpoint and uniform knots: the
core interpolates the particles (plume._native.interpolate_surface), a SURFACE object is built from
its control points by the add-on's builder (nu NURBS rows of nv points joined by Make Segment into
one net), and the vertices of the object's evaluated mesh must equal plume._native.tessellate()
(<= 1e-4 of the domain size). The same for least-squares nets with fewer control points than
particles (plume._native.fit_surface, what Build Surfaces makes), orders 4, 3 and 2 across the
streaklines.

Uses the installed add-on's native module (CI installs the fresh build before running this).
Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_nurbs_tessellation.py
"""

import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import native, reset_scene, run  # noqa: E402

DOMAIN_SIZE = 1.0
STREAKLINES = (2, 3, 5, 11)
PARTICLES = (1, 2, 3, 4, 7)
RESOLUTION_U, RESOLUTION_V = 3, 2  # different, so a u/v mix-up cannot pass


def particles(nv, nu, seed):
    """Particles (nv, nu, 3) of a rising, twisting sheet with a little noise, in a unit domain."""
    rng = np.random.default_rng(seed)
    s = np.linspace(0.0, 1.0, nu)[None, :] * np.ones((nv, 1))
    t = np.linspace(0.0, 1.0, nv)[:, None] * np.ones((1, nu))
    p = np.stack([0.5 + 0.3 * (t - 0.5) * np.cos(3 * s), 0.5 + 0.3 * (t - 0.5) * np.sin(3 * s),
                  0.1 + 0.8 * s], axis=-1)
    return p + rng.uniform(-0.02, 0.02, p.shape)


def surface_object(name, surface, resolution_u, resolution_v):
    """A SURFACE object with the core's control net, made by the add-on's own builder (rows joined
    by Make Segment; with 2 streaklines, which 3.4.1 leaves unmerged, one row extruded once), so
    the test checks the objects Build Surfaces makes."""
    from plume.build.surfaces import surface_object as make_net
    nu, nv = surface["nu"], surface["nv"]
    ob = make_net(name, bpy.context.scene.collection, nu, nv, bpy.context.view_layer)
    cu = ob.data
    sp = cu.splines[0]
    co = np.asarray(surface["control_points"], dtype=np.float32)  # (nv*nu, 4), flat v*nu+u
    sp.points.foreach_set("co", co.ravel())
    sp.order_u, sp.order_v = surface["order_u"], surface["order_v"]
    sp.use_endpoint_u, sp.use_endpoint_v = surface["endpoint_u"], surface["endpoint_v"]
    sp.resolution_u, sp.resolution_v = resolution_u, resolution_v
    cu.update_tag()
    return ob


def evaluated_vertices(ob):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    ob_eval = ob.evaluated_get(depsgraph)
    mesh = ob_eval.to_mesh()
    try:
        co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", co)
    finally:
        ob_eval.to_mesh_clear()
    return co.reshape(-1, 3)


class NurbsTessellationTest(unittest.TestCase):
    worst = 0.0  # largest Blender/core vertex difference seen

    @classmethod
    def tearDownClass(cls):
        print(f"largest difference between Blender's and the core's vertices: {cls.worst:.3g}")

    @classmethod
    def setUpClass(cls):
        reset_scene()
        bpy.context.view_layer.update()  # drop the removed default objects from the view layer
        cls.native = native()
        if not hasattr(cls.native, "interpolate_surface"):
            raise RuntimeError("the installed plume._native has no interpolate_surface: install "
                               "the add-on with a fresh build of the native module")

    def check(self, nv, nu, endpoint_u, endpoint_v):
        pts = particles(nv, nu, seed=100 * nv + nu)
        s = self.native.interpolate_surface(pts, order_u=4, order_v=4, endpoint_u=endpoint_u,
                                            endpoint_v=endpoint_v)
        # The core's surface goes through every particle.
        u, v = np.meshgrid(s["params_u"][:nu], s["params_v"][:nv])
        self.assertLessEqual(np.abs(self.native.surface_point(s, u, v) - pts).max(),
                             1e-5 * DOMAIN_SIZE)
        ob = surface_object(f"S_{nv}_{nu}", s, RESOLUTION_U, RESOLUTION_V)
        try:
            sp = ob.data.splines[0]
            self.assertEqual((sp.order_u, sp.order_v), (s["order_u"], s["order_v"]))
            got = evaluated_vertices(ob)
            expect = self.native.tessellate(s, RESOLUTION_U, RESOLUTION_V).reshape(-1, 3)
            self.assertEqual(got.shape, expect.shape)
            err = float(np.abs(got - expect).max())
            type(self).worst = max(type(self).worst, err)
            self.assertLessEqual(err, 1e-4 * DOMAIN_SIZE, f"max vertex difference {err}")
        finally:
            curve = ob.data
            bpy.data.objects.remove(ob, do_unlink=True)
            bpy.data.curves.remove(curve)
            bpy.context.view_layer.update()



def _check_fit(self, lines, particles, nu, nv, order_v):
    pts = particles_of(lines, particles, seed=7 * lines + particles)
    s = self.native.fit_surface(pts, nu=nu, nv=nv, order_v=order_v)
    self.assertEqual((s["nu"], s["nv"], s["order_v"]), (nu, nv, min(order_v, nv)))
    ob = surface_object(f"F_{lines}_{particles}", s, RESOLUTION_U, RESOLUTION_V)
    try:
        got = evaluated_vertices(ob)
        expect = self.native.tessellate(s, RESOLUTION_U, RESOLUTION_V).reshape(-1, 3)
        err = float(np.abs(got - expect).max())
        type(self).worst = max(type(self).worst, err)
        self.assertLessEqual(err, 1e-4 * DOMAIN_SIZE, f"max vertex difference {err}")
    finally:
        curve = ob.data
        bpy.data.objects.remove(ob, do_unlink=True)
        bpy.data.curves.remove(curve)
        bpy.context.view_layer.update()


particles_of = particles


def _add_fit_case(lines, count, nu, nv, order_v):
    def test(self):
        _check_fit(self, lines, count, nu, nv, order_v)
    test.__doc__ = f"fit of {lines} streaklines x {count} particles on a {nu} x {nv} net"
    setattr(NurbsTessellationTest, f"test_fit_{lines:02d}x{count}_net_{nu}x{nv}_o{order_v}", test)


for _case in ((5, 7, 5, 3, 4), (11, 40, 12, 6, 4), (3, 20, 6, 3, 3), (2, 9, 4, 2, 4),
              (11, 40, 9, 11, 2)):
    _add_fit_case(*_case)


def _add_case(nv, nu, endpoint_u, endpoint_v):
    """One test method per size and knot type, so the summary counts cases."""
    kind = {(True, True): "endpoint", (False, False): "uniform"}.get(
        (endpoint_u, endpoint_v), f"endpoint_u{int(endpoint_u)}_v{int(endpoint_v)}")

    def test(self):
        self.check(nv, nu, endpoint_u, endpoint_v)
    test.__doc__ = f"{nv} streaklines x {nu} particles, {kind} knots"
    setattr(NurbsTessellationTest, f"test_{kind}_{nv:02d}x{nu}", test)


for _nv in STREAKLINES:
    for _nu in PARTICLES:
        _add_case(_nv, _nu, True, True)
        _add_case(_nv, _nu, False, False)
for _nv, _nu in ((3, 7), (5, 4), (11, 3), (2, 4)):
    _add_case(_nv, _nu, True, False)
    _add_case(_nv, _nu, False, True)


if __name__ == "__main__":
    run(NurbsTessellationTest)
