"""Structural flames, structure side, from Python ([Structural Flames] §4.1-4.3, §6.1-6.2):
settings checks, spine fitting and re-sampling, wind fields (a grid from NumPy), obstacles,
the flame system's arrays, determinism and the breakaway statistics."""
import math

import numpy as np
import pytest

import _native

DT = 1.0 / 24.0


def test_bad_params_name_setting_and_range():
    for name, value, words in [("points", 1, "[2, 256]"),
                               ("height_persistent", 0.5, "H_p"),
                               ("height_max", 0.1, "H_max"),
                               ("lifespan_scale", 5.0, "lifespan_scale (A)")]:
        p = _native.FlameParams()
        setattr(p, name, value)
        with pytest.raises(ValueError, match=r".*" + words.replace("[", r"\[").replace("(", r"\(")
                           .replace(")", r"\)")):
            p.validate()
        with pytest.raises(ValueError):
            _native.FlameSystem(p, 1)
    s = _native.FlameSource()
    s.end_time = -1.0
    with pytest.raises(ValueError, match="sources\\[0\\].end_time"):
        _native.FlameSystem(_native.FlameParams(), 1).add_source(s)


def test_spine_interpolates_and_resamples_evenly():
    u = np.array([0.0, 0.1, 0.15, 0.4, 0.7, 1.0])
    pts = np.stack([0.1 * np.sin(3 * u), 0 * u, 0.5 * u], axis=1)
    spine = _native.Spine(pts)
    # Passes through its points at its knots (rounding only).
    np.testing.assert_allclose(spine.evaluate(spine.knots), pts, atol=1e-12)
    r = _native.spine_resample(pts, 11)
    assert r.shape == (11, 3)
    assert np.array_equal(r[0], pts[0]) and np.array_equal(r[-1], pts[-1])
    # Even arc length, measured on a dense polyline of the curve (2e5 chords: ~1e-10 m error;
    # nearest-sample lookup within one chord, 3e-6 m).
    dense = spine.evaluate(np.linspace(0.0, spine.knots[-1], 200001))
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(dense, axis=0), axis=1))])
    near = [np.argmin(np.linalg.norm(dense - p, axis=1)) for p in r]
    np.testing.assert_allclose(s[near], np.linspace(0, s[-1], 11), atol=1e-5)
    assert spine.length == pytest.approx(s[-1], rel=1e-8)


def test_wind_fields_from_numpy():
    values = np.zeros((4, 4, 4, 3), np.float32)
    values[..., 0] = np.arange(4)[:, None, None]  # u = i
    grid = _native.GridWind(values, 0.5, (0.0, 0.0, 0.0))
    w = grid.evaluate(np.array([[0.25 + 0.5 * 1.5, 1.0, 1.0]]))
    assert w[0, 0] == pytest.approx(1.5, abs=1e-6)  # trilinear on a linear field: exact
    u, v, w = np.zeros((4, 3, 3)), np.zeros((3, 4, 3)), np.full((3, 3, 4), 2.0)
    mac = _native.MacWind(u, v, w, 0.1, (0.0, 0.0, 0.0))
    assert mac.evaluate(np.array([[0.12, 0.2, 0.05]]))[0] == pytest.approx([0.0, 0.0, 2.0])
    with pytest.raises(ValueError):
        _native.MacWind(u, u, w, 0.1, (0.0, 0.0, 0.0))
    turb = _native.TurbulenceWind(0.5, 0.3, 1.0, 7)
    x = np.random.default_rng(1).uniform(-3, 3, (4000, 3))
    rms = math.sqrt(np.mean(np.sum(turb.evaluate(x, 0.3) ** 2, axis=1)))
    assert rms == pytest.approx(0.5, rel=0.1)  # cross terms of the modes average out to a few %
    vortex = _native.VortexWind((0, 0, 0), (0, 0, 1), 2.0, 0.1)
    assert vortex.evaluate(np.array([[1.0, 0.0, 0.0]]))[0] == pytest.approx([0.0, 2.0, 0.0])


def torch(seed, speed=1.5):
    p = _native.FlameParams()
    p.points = 12
    system = _native.FlameSystem(p, seed)
    for k in range(5):
        src = _native.FlameSource()
        a = 2 * math.pi * k / 5
        src.position = (0.04 * math.cos(a), 0.04 * math.sin(a), 1.0)
        src.velocity = (speed, 0.0, 0.0)
        system.add_source(src)
    system.add_wind(_native.TurbulenceWind(0.3, 0.2, 1.0, seed))
    return system


def test_flame_arrays_and_trailing_torch():
    system = torch(3)
    for _ in range(24):
        system.step(DT)
    flames = system.flames()
    attached = [f for f in flames if not f["separated"]]
    assert len(attached) == 5
    for f in flames:
        n = len(f["points"])
        assert f["points"].shape == (n, 3) and f["velocities"].shape == (n, 3)
        assert f["ages"].shape == (n,) and n >= 2
    for f in attached:
        assert f["points"].shape[0] == 12
        # Figure 1: a torch moving along +x trails its flames along -x, rising by buoyancy.
        tip, base = f["points"][-1], f["points"][0]
        assert tip[0] < base[0] - 0.05 and tip[2] > base[2]
        assert f["ages"][0] == 0.0 and np.all(np.diff(f["ages"]) > 0)
    assert len({f["id"] for f in flames}) == len(flames)


def test_same_seed_same_flames_other_seed_differs():
    a, b, c = torch(5), torch(5), torch(6)
    for _ in range(30):
        for s in (a, b, c):
            s.step(DT)
    fa, fb, fc = a.flames(), b.flames(), c.flames()
    assert [f["id"] for f in fa] == [f["id"] for f in fb]
    assert all(np.array_equal(x["points"], y["points"]) for x, y in zip(fa, fb))
    assert not all(len(x["points"]) == len(y["points"]) and np.array_equal(x["points"], y["points"])
                   for x, y in zip(fa, fc))


def test_obstacle_keeps_points_outside():
    p = _native.FlameParams()
    system = _native.FlameSystem(p, 2)
    system.add_source(_native.FlameSource())
    system.add_wind(_native.UniformWind((1.5, 0.0, 0.0)))
    sphere = _native.SphereSdf((0.25, 0.0, 0.08), 0.08)
    system.add_obstacle(sphere)
    for _ in range(48):
        system.step(DT)
        for f in system.flames():
            pts = f["points"] if f["separated"] else f["points"][1:]
            assert np.all(sphere.distance(pts) >= -1e-9)


def test_breakaway_statistics():
    p = _native.FlameParams()
    p.points = 6
    p.height_persistent, p.height_intermittent, p.height_max = 0.05, 0.1, 100.0
    p.breakaway_frequency = 5.0
    p.separated_can_split = False
    system = _native.FlameSystem(p, 9)
    for k in range(4):
        src = _native.FlameSource()
        src.position = (0.3 * k, 0.0, 0.0)
        system.add_source(src)
    for _ in range(24 * 150):
        system.step(DT)
    st = system.statistics
    # ~3000 breaks: Poisson SE ~1.8%, so 10% is > 5 SE.
    assert st["breakaways"] > 2500
    assert st["breakaways"] / st["eligible_time"] == pytest.approx(5.0, rel=0.1)
    assert st["forced_breakaways"] == 0


def test_noise_bounds_are_the_ones_setting_ranges_gives():
    """The noises' ranges the add-on reads (setting_ranges) are the ones the core enforces: the
    spine's Kolmogorov velocity through FlameParams, the render noises through FlameShaper. A
    scale's lower bound (0) is excluded, a drift's bounds are per component."""
    every = _native.setting_ranges()
    profiles = [_native.FlameProfile.library("torch")]

    def spine(name, value):
        p = _native.FlameParams()
        setattr(p, "spine_noise_amplitude" if name == "spine_noise" else name,
                (0.0, 0.0, value) if name.endswith("drift") else value)
        p.validate()

    def shaper(name, value):
        key = {"kolmogorov": "kolmogorov_amplitude", "flow_noise": "flow_noise_amplitude"}.get(
            name, name)
        _native.FlameShaper(profiles, **{key: (0.0, 0.0, value) if name.endswith("drift")
                                         else value}, kolmogorov_resolution=8)

    for name in ("spine_noise", "spine_noise_scale", "spine_noise_frequency",
                 "spine_noise_drift", "flow_noise", "flow_noise_scale", "flow_noise_frequency",
                 "flow_noise_rotation", "kolmogorov", "kolmogorov_scale",
                 "kolmogorov_frequency", "kolmogorov_drift"):
        lo, hi = every["flames." + name]
        check = spine if name.startswith("spine") else shaper
        check(name, hi)
        with pytest.raises(ValueError, match=name.split("_")[0]):
            check(name, hi * 1.001)
        if name.endswith("scale"):
            with pytest.raises(ValueError, match=r"\(0, "):
                check(name, lo)
        else:
            check(name, lo)
            with pytest.raises(ValueError):
                check(name, lo - 1e-3 if lo == 0 else lo * 1.001)


def test_spine_noise_moves_the_flames_and_is_seeded():
    """§4.2: v_K has the RMS of its amplitude; off, the flames of eq. 1 without it."""
    p = _native.FlameParams()
    s = _native.FlameSystem(p, 3)
    x = np.random.default_rng(0).uniform(-1.0, 1.0, (4000, 3))
    v = s.spine_noise_velocity(x, 0.5)
    rms = float(np.sqrt((v ** 2).sum(axis=1).mean()))
    # Off the lattice, trilinear reading lowers the variance a little: within 25%.
    assert 0.75 * p.spine_noise_amplitude < rms <= 1.05 * p.spine_noise_amplitude
    np.testing.assert_array_equal(v, _native.FlameSystem(p, 3).spine_noise_velocity(x, 0.5))
    assert not np.array_equal(v, _native.FlameSystem(p, 4).spine_noise_velocity(x, 0.5))
    p.spine_noise_amplitude = 0.0
    assert not _native.FlameSystem(p, 3).spine_noise_velocity(x, 0.5).any()
