"""plume._native's streak-surface NURBS from Python ([Smoke Surfaces] §3.3-3.4)."""
import numpy as np
import pytest

import _native


def sheet(nv, nu, seed=0):
    """Particles (nv, nu, 3) of nv streaklines with nu particles each, in a unit domain."""
    rng = np.random.default_rng(seed)
    s = np.linspace(0.0, 1.0, nu)[None, :] * np.ones((nv, 1))
    t = np.linspace(0.0, 1.0, nv)[:, None] * np.ones((1, nu))
    p = np.stack([0.5 + 0.3 * (t - 0.5) * np.cos(3 * s), 0.5 + 0.3 * (t - 0.5) * np.sin(3 * s),
                  0.1 + 0.8 * s], axis=-1)
    return p + rng.uniform(-0.02, 0.02, p.shape)


def test_knots_are_blenders():
    assert _native.nurbs_knots(5, 4, True).tolist() == [0, 0, 0, 0, 1, 2, 2, 2, 2]
    assert _native.nurbs_knots(4, 3, False).tolist() == list(range(7))
    assert _native.nurbs_domain(7, 4, False) == (3.0, 7.0)
    assert _native.nurbs_samples(3, 2, True, 2).shape == (6,)
    with pytest.raises(ValueError, match="order"):
        _native.nurbs_knots(3, 4, True)


@pytest.mark.parametrize("endpoint", [True, False])
@pytest.mark.parametrize("nv", [2, 3, 5, 11])
@pytest.mark.parametrize("nu", [1, 2, 3, 4, 7])
def test_surface_passes_through_every_particle(nu, nv, endpoint):
    pts = sheet(nv, nu)
    s = _native.interpolate_surface(pts, endpoint_u=endpoint, endpoint_v=endpoint)
    assert s["control_points"].shape == (s["nu"] * s["nv"], 4)
    assert (s["nu"], s["nv"]) == (max(nu, 2), max(nv, 2))
    assert np.all(s["control_points"][:, 3] == 1.0)
    u, v = np.meshgrid(s["params_u"][:nu], s["params_v"][:nv])
    assert np.abs(_native.surface_point(s, u, v) - pts).max() <= 1e-5


def test_tessellate_is_the_grid_of_blender_samples():
    s = _native.interpolate_surface(sheet(3, 5), order_v=3)
    t = _native.tessellate(s, resolution_u=2, resolution_v=3)
    assert t.shape == (10, 9, 3)
    us = _native.nurbs_samples(5, 4, True, 2)
    vs = _native.nurbs_samples(3, 3, True, 3)
    uu, vv = np.meshgrid(us, vs, indexing="ij")
    assert np.abs(_native.surface_point(s, uu, vv) - t).max() < 1e-6


def test_normals_are_unit():
    s = _native.interpolate_surface(sheet(4, 6))
    n = _native.surface_normal(s, np.linspace(0, 3, 7), 0.5)
    assert n.shape == (7, 3)
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-5)


def test_density_map_and_mesh_export():
    density = np.zeros((10, 10, 10), np.float32)
    density[3:7, 3:7, 2:8] = 1.0
    pts = sheet(3, 5)
    s = _native.interpolate_surface(pts)
    m = _native.density_map(s, density, (0.0, 0.0, 0.0), 0.1, k_u=4, k_v=2)
    assert m.shape == ((3 - 1) * 3 + 1, (5 - 1) * 5 + 1)
    assert m.dtype == np.float32 and 0.0 <= m.min() and m.max() <= 1.0 + 1e-6
    linear = _native.density_map(pts, density, (0, 0, 0), 0.1, k_u=0, k_v=0,
                                 interpolation=_native.Interpolation.LINEAR)
    assert linear.shape == (3, 5)
    with pytest.raises(ValueError, match="sampling_u"):
        _native.density_map(s, density, (0, 0, 0), 0.1, k_u=-1)
    verts, quads, dens = _native.subdivide_mesh(s["control_points"], s["nu"], s["nv"], 2, m)
    assert verts.shape == (((5 - 1) * 4 + 1) * ((3 - 1) * 4 + 1), 3)
    assert quads.shape == (4 * 2 * 16, 4) and quads.max() < len(verts)
    assert dens.shape == (len(verts),)
    _, _, none = _native.subdivide_mesh(s["control_points"][:, :3], 5, 3, level=1)
    assert none is None
    with pytest.raises(ValueError, match="level"):
        _native.subdivide_mesh(s["control_points"], 5, 3, level=9)


def test_density_map_converges_in_1d():
    errors = [_native.density_map_error_1d(lambda t: np.exp(-((t - 0.4) / 0.08) ** 2), 6, k)["rms"]
              for k in (0, 1, 2, 4, 8)]
    assert all(a > b for a, b in zip(errors, errors[1:]))


def test_bad_points_raise_value_error():
    with pytest.raises(ValueError, match="shape"):
        _native.interpolate_surface(np.zeros((3, 4)))
    with pytest.raises(ValueError, match="finite"):
        _native.interpolate_surface(np.full((2, 2, 3), np.nan))
    with pytest.raises(ValueError, match="order_u"):
        _native.interpolate_surface(sheet(2, 3), order_u=7)


# --- the least-squares streak surface (§3.3 with an editable net) ---------------------------

def rising_shot(frames=12, lines=4, steps=2):
    """Points (frames, lines, particles, 3) float32 of a swirling rising plume and keep flags:
    particles born so far (the unborn slots hold garbage the fit must ignore)."""
    particles = frames * steps
    pts = np.full((frames, lines, particles, 3), 1e6, np.float32)
    keep = np.zeros((frames, lines, particles), np.uint8)
    for f in range(frames):
        born = (f + 1) * steps
        age = (born - 1 - np.arange(born)) / (24.0 * steps)
        for b in range(lines):
            ph = 2 * np.pi * b / lines
            fan = 0.02 + 0.08 * age
            pts[f, b, :born] = np.stack([0.5 + fan * np.cos(ph + 3 * age),
                                         0.5 + fan * np.sin(ph + 3 * age),
                                         0.05 + 0.1 * age + 0.2 * age ** 2], -1)
            keep[f, b, :born] = 1
    return pts, keep


def test_fit_surface_stays_within_its_residual():
    pts, keep = rising_shot()
    s = _native.fit_surface(pts[-1], keep[-1], nu=8, nv=4)
    assert (s["nu"], s["nv"], s["order_u"], s["order_v"]) == (8, 4, 4, 4)
    assert s["params_u"].shape == pts.shape[1:3]
    k = keep[-1] > 0
    u = s["params_u"][k]
    v = np.broadcast_to(s["params_v"][:, None], k.shape)[k]
    err = np.linalg.norm(_native.surface_point(s, u, v) - pts[-1][k], axis=-1)
    assert err.max() <= s["max_residual"] + 1e-6
    assert s["max_residual"] < 0.01
    assert np.isnan(s["params_u"][~k]).all()
    with pytest.raises(ValueError, match="keep must be flags"):
        _native.fit_surface(pts[-1], keep[-1, :2], nu=8, nv=4)
    with pytest.raises(ValueError, match="no particle is kept"):
        _native.fit_surface(pts[-1], np.zeros_like(keep[-1]), nu=8, nv=4)


def test_fit_streak_shot_chooses_one_net_for_every_frame():
    pts, keep = rising_shot()
    cell = 1.0 / 40
    shot = _native.fit_streak_shot(pts, keep, tolerance=0.5 * cell, net_tolerance=1.5 * cell)
    frames, lines, particles = keep.shape
    assert 4 <= shot["nu"] < particles and 2 <= shot["nv"] <= lines
    assert shot["control_points"].shape == (frames, shot["nu"] * shot["nv"], 4)
    # The 4 lines fan around the plume's axis: a cubic through them swings off, so the rows are
    # the lines' own curves (the particle net across), a smooth tube that cuts the fan's corners
    # by 1.40 cells (measured), where order 2 drew a square one through them.
    assert shot["particle_net_v"] and shot["order_v"] == 4
    assert shot["max_residual"].max() <= 1.5 * cell
    assert shot["net_deviation"].max() <= 1.5 * cell
    assert len(shot["params_u"]) == frames
    fixed = _native.fit_streak_shot(pts, keep, tolerance=cell, net_tolerance=cell, nu=6, nv=3,
                                    order_v=3)
    assert (fixed["nu"], fixed["nv"], fixed["order_v"]) == (6, 3, 3)
    with pytest.raises(ValueError, match="tolerance"):
        _native.fit_streak_shot(pts, keep, tolerance=0.0, net_tolerance=cell)
    with pytest.raises(ValueError, match="keep must have shape"):
        _native.fit_streak_shot(pts, keep[:-1], tolerance=cell, net_tolerance=cell)


def test_control_point_frames_turn_with_the_surface():
    pts, keep = rising_shot()
    s = _native.fit_surface(pts[-1], keep[-1], nu=8, nv=4)
    axes, valid = _native.control_point_frames(s)
    assert axes.shape == (32, 3, 3) and valid.all()
    np.testing.assert_allclose(np.einsum("nij,nkj->nik", axes, axes),
                               np.broadcast_to(np.eye(3), axes.shape), atol=1e-12)
    turn = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # 90° about z
    turned = dict(s, control_points=s["control_points"].copy())
    turned["control_points"][:, :3] = s["control_points"][:, :3] @ turn.T
    after, _ = _native.control_point_frames(turned)
    np.testing.assert_allclose(after, axes @ turn.T, atol=1e-5)


def test_density_map_on_domain_is_zero_outside_the_grid():
    pts = sheet(3, 6)
    s = _native.interpolate_surface(pts)
    grid = np.ones((16, 16, 8), np.float32)
    # The grid covers [0, 1]^2 x [0, 0.5] only: the sheet (z from 0.1 to 0.9) leaves it at the top.
    img = _native.density_map_on_domain(s, grid, (0.0, 0.0, 0.0), 0.0625, 11, 5)
    assert img.shape == (5, 11)
    u = np.linspace(*s["domain_u"], 11)
    v = np.linspace(*s["domain_v"], 5)
    z = _native.surface_point(s, *np.meshgrid(u, v))[..., 2]
    assert np.all(img[z > 0.5] == 0.0) and np.all(img[z < 0.49] == 1.0)
    with pytest.raises(ValueError, match="count >= 2"):
        _native.density_map_on_domain(s, grid, (0.0, 0.0, 0.0), 0.0625, 1, 5)
