"""The streak surfaces' control nets stay on the smoke ([Smoke Surfaces] §3.3 as a
least-squares fit instead of an interpolation of every particle slot).

Three bakes: the Figure 1 example itself (make_source and make_domain of
examples/streak_surfaces/incense.py:
50³, one tip cell with 20 point sources, its 120 frames, the Most Surfaces threshold), where the
top of the plume scatters late in the shot and the control points along the streaklines are the
particles (the cubic particle net: the sheet cuts the corners of the scatter);
the same set-up reduced to 40 frames; and a 2 m domain at 40³ with a UV-sphere Source of radius
0.25 m (one point source per cell: 256 streaklines), 60 frames, default threshold (all of them
in one sheet); and that scene with every default (a rim of point sources: a few sheets). For
every surface on every frame: no control point is farther than ν from the nearest particle of
its surface it goes through (3 cells, or half the largest gap between consecutive particles of a
streakline where the particles are sparser), and the sheet passes within the fit tolerance
(streak_surfaces.FIT_TOLERANCE_CELLS) of every particle it goes through (fit_mask: emitted, not
past an open side) — within ν where the rows of the net are the lines' curves (the particle net
across), and with its control points on the particles where they are along u. The surface cache
holds the fitted points and Blender's net has their size and orders (an order-2 net drawn with
one sample per control point); on the reduced incense and the sphere scene the nets stay cubic
along the streaklines, with fewer control points than particles, and on the sphere scene none is
outside the domain. The interpolating nets of the same particles (the surfaces before the fit)
are printed for comparison.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_streak_net.py
"""

import os
import sys
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "examples", "streak_surfaces"))  # incense

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import (add_domain, add_sphere_source, reset_scene, rmtree, run,  # noqa: E402
                     select_only, temp_dir)

NEAR_CELLS = 3.0  # no control point farther than this from the nearest particle of its surface
#: Largest distance, cells, from a particle to a sheet whose rows are the lines' curves (below).
ACROSS_CELLS = 12.0


def near_cells(full, keep, cell):
    """ν of a frame in cells (native shot_fit.cpp): NEAR_CELLS, or half the largest gap between
    consecutive kept particles of a streakline where that is larger."""
    gap = 0.0
    for line, kept in zip(full, keep):
        pts = np.asarray(line[kept], np.float64)
        if len(pts) > 1:
            gap = max(gap, float(np.linalg.norm(np.diff(pts, axis=0), axis=1).max()))
    return max(NEAR_CELLS, 0.5 * gap / cell)


def nearest(points, cloud):
    """Distance from each of points (n, 3) to the nearest of cloud (m, 3), float64."""
    cloud = np.unique(np.asarray(cloud, np.float64), axis=0)
    cc = (cloud * cloud).sum(1)
    out = np.empty(len(points))
    for i in range(0, len(points), 512):
        p = np.asarray(points[i:i + 512], np.float64)
        d = (p * p).sum(1)[:, None] + cc[None, :] - 2.0 * (p @ cloud.T)
        out[i:i + 512] = np.sqrt(np.maximum(d.min(1), 0.0))
    return out


class StreakNetTest(unittest.TestCase):
    def setUp(self):
        reset_scene()
        self.tmp = temp_dir("plume_streak_net_")
        self.cache = os.path.join(self.tmp, "cache")

    def tearDown(self):
        rmtree(self.tmp)

    def bake_and_build(self, dom, most_surfaces):
        select_only(dom)
        t0 = time.perf_counter()
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        t1 = time.perf_counter()
        if most_surfaces:
            self.assertEqual(bpy.ops.plume.surfaces_pick_threshold(), {'FINISHED'})
        self.assertEqual(bpy.ops.plume.surfaces_build(), {'FINISHED'})
        print(f"  bake {t1 - t0:.1f} s, Build Surfaces {time.perf_counter() - t1:.1f} s")

    def check_nets(self, dom, label):
        """Asserts the two bounds on every surface and frame; returns the figures."""
        from plume import _native, cache
        from plume import streak_surfaces as ss
        from plume.operators.surfaces import compute_distances
        folder, m, frames, groups = compute_distances(dom)
        cell = float(m["cell_size"])
        lo = np.asarray(m["origin"], np.float64)
        hi = lo + np.asarray(m["resolution"]) * cell
        plans = ss.plan_surfaces(_native, groups, dom.plume.domain.streak_threshold)
        obs = [bpy.data.objects[f"{dom.name}_surface_{i}"] for i in range(len(plans))]
        fig = dict(net=[], orders=[], particles=[], cp=0.0, cp_kept=0.0, residual=0.0,
                   old_cp=0.0, outside=0, points=0, near_ratio=0.0, particle_nets=[],
                   fitted_residual=0.0, across_residual=0.0)
        for i, (plan, ob) in enumerate(zip(plans, obs)):
            anim = ss.surface_animation(_native, frames, plan, cell, box=(lo, hi))
            with np.load(cache.surface_path(folder, i)) as z:
                np.testing.assert_array_equal(z["control_points"], anim.control_points)
            sp = ob.data.splines[0]
            self.assertEqual((sp.point_count_u, sp.point_count_v), (anim.nu, anim.nv))
            self.assertEqual((sp.order_u, sp.order_v), (anim.order_u, anim.order_v))
            # An order-2 net is drawn with its samples on its control points (the particles).
            self.assertEqual(sp.resolution_u, 1 if anim.order_u == 2 else 2)
            fig["net"].append(f"{anim.nu}x{anim.nv}")
            fig["orders"].append((anim.order_u, anim.order_v))
            fig["particles"].append(anim.particles)
            fig["particle_nets"].append((anim.particle_net_u, anim.particle_net_v))
            for f, frame in enumerate(frames):
                full = ss.streakline_grid(frame, plan.sources, anim.particles)
                counts = np.asarray(frame["counts"])[plan.sources]
                born = np.arange(anim.particles)[None, :] < counts[:, None]
                s = anim.surfaces[f]
                keep = s["keep"]
                cp = anim.control_points[f][:, :3]
                fig["cp"] = max(fig["cp"], nearest(cp, full[born]).max() / cell)
                kept_cp = nearest(cp, full[keep]).max() / cell
                fig["cp_kept"] = max(fig["cp_kept"], kept_cp)
                fig["near_ratio"] = max(fig["near_ratio"], kept_cp / near_cells(full, keep, cell))
                u = s["params_u"][keep]
                v = np.broadcast_to(s["params_v"][:, None], keep.shape)[keep]
                res = np.linalg.norm(_native.surface_point(s, u, v) - full[keep], axis=-1) / cell
                fig["residual"] = max(fig["residual"], res.max())
                if anim.particle_net_u:
                    # The control points along u are the particles: the sheet cuts each zig-zag's
                    # corner by |Δ²p|/6 on the uniform interior knots, more where the end knots
                    # clamp (measured here, not bounded).
                    self.assertEqual(kept_cp, 0.0)
                elif anim.particle_net_v:
                    fig["across_residual"] = max(fig["across_residual"], res.max())
                else:
                    fig["fitted_residual"] = max(fig["fitted_residual"], res.max())
                if f == len(frames) - 1:
                    fig["outside"] += int(np.any((cp < lo - 1e-6) | (cp > hi + 1e-6), axis=1).sum())
                    fig["points"] += len(cp)
                    old = _native.interpolate_surface(full, order_u=ss.ORDER_U,
                                                      order_v=ss.ORDER_V)["control_points"]
                    fig["old_cp"] = max(fig["old_cp"], nearest(old[:, :3], full[born]).max() / cell)
        orders = ", ".join(f"{u}x{v}" + ("p" if pu else "") + ("P" if pv else "")
                           for (u, v), (pu, pv) in zip(fig["orders"], fig["particle_nets"]))
        print(f"  {label}: {len(plans)} surfaces, nets {', '.join(fig['net'])} (orders {orders}; "
              f"p: the particle net along u, P: across; largest residual of the fitted nets "
              f"{fig['fitted_residual']:.3f} cells, of those with the particle net across only "
              f"{fig['across_residual']:.3f}; control points up to {fig['near_ratio']:.2f} of ν; "
              f"particles per "
              f"streakline {max(fig['particles'])}); farthest control point from the nearest "
              f"particle {fig['cp']:.2f} cells ({fig['cp_kept']:.2f} from those fitted); largest "
              f"particle-to-sheet residual {fig['residual']:.3f} cells (tolerance "
              f"{ss.FIT_TOLERANCE_CELLS}); last frame: {fig['outside']} of {fig['points']} control "
              f"points outside the domain; the interpolating net of the last frame: "
              f"{fig['old_cp']:.1f} cells")
        # ν of each frame (the largest gap between consecutive particles halved, where larger).
        self.assertLessEqual(fig["near_ratio"], 1.0 + 1e-6)
        # ε where the net is fitted. Where its rows are the lines' curves (the particle net
        # across), the sheet rounds each zig-zag of neighbouring lines in the greedy order, missing
        # the middle line by about |Δ²p|/6: in the stirred plume of today's defaults the lines of
        # an arc cross one another and the sheet passes up to 10.9 cells from a line (measured,
        # bpy 4.5: 10.93 with Placement Cells, 9.83 with the rim; 1.24 on the incense), where
        # order 2 went through them with a crease at each.
        self.assertLessEqual(fig["fitted_residual"], ss.FIT_TOLERANCE_CELLS * (1 + 1e-6))
        self.assertLessEqual(fig["across_residual"], ACROSS_CELLS)
        return fig

    def incense(self, frames):
        """The set-up of examples/streak_surfaces/incense.py (its own functions) over `frames`
        frames."""
        import incense
        incense.make_source(frames)
        dom = incense.make_domain(frames)
        dom.plume.domain.cache_directory = self.cache + "/"
        self.bake_and_build(dom, most_surfaces=True)
        fig = self.check_nets(dom, f"incense, {frames} frames")
        self.assertGreaterEqual(len(fig["net"]), 2)
        return fig

    def test_figure_1_example(self):
        import incense
        fig = self.incense(incense.DEFAULT_FRAMES)
        # The scatter at the top is met by one control point per particle, on the particles,
        # drawn cubic (the particle net; order 2 drew them as flat facets).
        self.assertEqual({u for u, _ in fig["orders"]}, {4})
        self.assertTrue(any(pu for pu, _ in fig["particle_nets"]))

    def test_figure_1_incense(self):
        fig = self.incense(40)
        # Smooth streaklines keep cubic nets, with fewer control points than particles.
        self.assertEqual({u for u, _ in fig["orders"]}, {4})
        self.assertLess(max(int(n.split("x")[0]) for n in fig["net"]), max(fig["particles"]))

    def test_sphere_source_at_40(self):
        """60 frames, as the scene was written for: late in the shot the top of the plume
        scatters and early on the particles are sparse (gaps of up to 13 cells at frame 18), so
        whether a control point lands within 3 cells of a particle (ν) changes from one count to
        the next; where consecutive particles are more than 2ν apart, ν is half their gap (a
        control point between them cannot be nearer). The fit also tries a few counts above the
        one it bisects (shot_fit.cpp): with Fast Velocity this sheet keeps a cubic net along the
        streaklines (38 points; 40 when ν was 3 cells on every frame, order 2 with 113 of 113
        before the scan)."""
        src = add_sphere_source(radius=0.25, location=(0.0, 0.0, 0.35))
        src.plume.source.point_placement = 'CELLS'
        src.plume.source.point_sources = 1
        dom = add_domain(resolution=40, frame_end=60, cache_directory=self.cache + "/")
        dom.plume.domain.streaks = True
        self.bake_and_build(dom, most_surfaces=False)
        fig = self.check_nets(dom, "sphere source, 40³, 60 frames")
        nu = [int(n.split("x")[0]) for n in fig["net"]]
        self.assertLess(max(nu), min(fig["particles"]))
        self.assertEqual({u for u, _ in fig["orders"]}, {4})
        self.assertEqual(fig["outside"], 0)

    def test_sphere_source_at_40_every_default(self):
        """The same scene with every default (a rim of point sources, the mean of h as h0): a
        few sheets, each of the paper's size, on the smoke."""
        add_sphere_source(radius=0.25, location=(0.0, 0.0, 0.35))
        dom = add_domain(resolution=40, frame_end=60, cache_directory=self.cache + "/")
        dom.plume.domain.streaks = True
        self.bake_and_build(dom, most_surfaces=False)
        fig = self.check_nets(dom, "sphere source, every default, 40³, 60 frames")
        widths = [int(n.split("x")[1]) for n in fig["net"]]
        self.assertTrue(2 <= len(widths) <= 8, widths)
        self.assertLessEqual(max(widths), 12)  # an arc of about 8 point sources (point_rim.py)
        self.assertEqual(fig["outside"], 0)


if __name__ == "__main__":
    run(StreakNetTest)
