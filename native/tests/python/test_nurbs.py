"""plume._native's streak-surface NURBS from Python (smoke_surfaces.txt §3.3-3.4)."""
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
