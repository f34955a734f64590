"""Toon smoke from Python ([Cartoon Smoke]): ToonParams, particles driven by NumPy
fields and by Plume volume frames, coherence (bounded size changes, shrink before death), birth,
the particle budget, determinism, billboards (Figure 4), the depth-differences filter (§2.2) and
toon files."""
import math

import numpy as np
import pytest

import _native

DT = 1.0 / 24.0
N = 10
RES = (N, N, 2 * N)
CELL = 0.1
ORIGIN = (0.0, 0.0, 0.0)


def plume_fields(scale=1.0, swirl=0.3):
    """A Gaussian column of smoke rising at 1 m/s and turning about the z axis."""
    nx, ny, nz = RES
    c = (np.arange(nx) + 0.5) * CELL
    x, y, z = np.meshgrid(c, (np.arange(ny) + 0.5) * CELL, (np.arange(nz) + 0.5) * CELL,
                          indexing="ij")
    axis = 0.5 * nx * CELL
    sigma = 0.2 * nx * CELL
    density = scale * np.exp(-((x - axis) ** 2 + (y - axis) ** 2) / (2 * sigma ** 2)) \
        * (1 - 0.6 * z / (nz * CELL))
    u = np.broadcast_to(-swirl * (y[:1] - axis), (nx + 1, ny, nz))
    v = np.broadcast_to(swirl * (x[:, :1] - axis), (nx, ny + 1, nz))
    w = np.ones((nx, ny, nz + 1))
    return _native.ToonFields(density.astype(np.float32), (u, v, w), 2 * density)


def params(**overrides):
    p = _native.ToonParams()
    p.birth_density, p.death_density = 0.5, 0.1
    p.birth_spacing = 0.0  # the paper's rule: a particle in every empty dense cell
    p.ramp_density_low, p.ramp_density_high = 0.1, 1.0
    p.size_low, p.size_high = 0.01, 0.05
    p.max_size_change = 0.1
    p.emission_count = 8
    p.seed = 3
    for key, value in overrides.items():
        setattr(p, key, value)
    return p


SOURCE = np.array([[4, 4, 0], [5, 4, 0], [4, 5, 0], [5, 5, 0]], np.int32)


def particles(**overrides):
    return _native.ToonParticles(params(**overrides), RES, ORIGIN, CELL)


def test_params_are_snake_case_and_bad_values_name_the_setting():
    p = params(integration=_native.ToonIntegration.MIDPOINT,
               color_driver=_native.ToonColorDriver.TEMPERATURE)
    p.validate()
    assert p.integration == _native.ToonIntegration.MIDPOINT
    assert p.ramp_size(0.55) == pytest.approx(0.03)
    for name, value in [("birth_density", 0.1), ("max_size_change", 0.0), ("max_count", 0),
                        ("cfl", 20.0), ("stretch_factor", -1.0), ("size_low", -0.5),
                        ("emission_count", -3), ("birth_spacing", -0.5), ("birth_spacing", 11.0)]:
        with pytest.raises(ValueError, match=name):
            params(**{name: value}).validate()
        with pytest.raises(ValueError, match=name):
            particles(**{name: value})
    with pytest.raises(ValueError, match="resolution"):
        _native.ToonParticles(params(), (0, 4, 4), ORIGIN, CELL)


def sizes_by_id(snap):
    return dict(zip(snap["ids"].tolist(), snap["size"].tolist()))


def test_sizes_change_at_most_one_step_per_frame_and_particles_never_pop():
    t = particles()
    step = 0.1 * 0.05
    strong, weak = plume_fields(), plume_fields(0.3, -0.5)
    for f in range(50):
        before = sizes_by_id(t.snapshot())
        odd = (f // 7) % 2 == 1
        t.advance_frame(weak if odd else strong, strong if odd else weak, DT, SOURCE)
        after = sizes_by_id(t.snapshot())
        for pid, size in before.items():
            # One float rounding of size +- step: 1e-6 relative.
            limit = step * (1 + 1e-6)
            assert abs(after.get(pid, 0.0) - size) <= limit, (f, pid)
        assert all(after[pid] == 0.0 for pid in after.keys() - before.keys())


def test_birth_fills_every_dense_empty_cell_within_one_frame():
    f = plume_fields()
    dense = np.argwhere(_dense() > 0.5)
    assert len(dense) > 20
    t = particles()
    for frame in range(20):
        t.advance_frame(f, f, DT, SOURCE)
        cells = {tuple(c) for c in np.floor(t.snapshot()["positions"] / CELL).astype(int)}
        assert all(tuple(c) in cells for c in dense), frame


def test_birth_spacing_keeps_newborns_apart_at_any_thread_count():
    """σ > 0: no two particles of a still, uniformly dense box closer than σ s(ρ) (their sizes
    are all s1 there), far fewer than one per cell, the same at one and two threads."""
    res = (16, 16, 16)
    still = _native.ToonFields(np.ones(res, np.float32),
                               tuple(np.zeros(tuple(n + (a == b) for b, n in enumerate(res)),
                                              np.float32) for a in range(3)))
    snaps = []
    for threads in (1, 2):
        t = _native.ToonParticles(params(birth_spacing=0.8, size_high=0.2, threads=threads), res,
                                  ORIGIN, CELL)
        for _ in range(4):
            t.advance_frame(still, still, DT)
        snaps.append(t.snapshot())
    x = snaps[0]["positions"].astype(np.float64)
    gaps = np.linalg.norm(x[:, None] - x[None], axis=2) + np.eye(len(x)) * 1e9
    assert gaps.min() >= 0.8 * 0.2 * (1 - 1e-5)
    assert 20 < len(x) < 16 ** 3 // 4  # measured 690 of 4096 cells (radius 1.6 cells)
    assert snaps[0]["positions"].tobytes() == snaps[1]["positions"].tobytes()


def test_count_stays_within_max_count_over_300_frames():
    f = plume_fields()
    t = particles(max_count=120, emission_count=30)  # fewer than the dense cells + emission
    counts = []
    for _ in range(300):
        t.advance_frame(f, f, DT, SOURCE)
        counts.append(t.count)
    assert max(counts) == 120
    assert t.frame == 300


def _dense():
    """The plume's density grid as plume_fields() builds it (ToonFields keeps no NumPy copy)."""
    nx, ny, nz = RES
    c = (np.arange(nx) + 0.5) * CELL
    x, y, z = np.meshgrid(c, c, (np.arange(nz) + 0.5) * CELL, indexing="ij")
    axis, sigma = 0.5 * nx * CELL, 0.2 * nx * CELL
    return np.exp(-((x - axis) ** 2 + (y - axis) ** 2) / (2 * sigma ** 2)) * (1 - 0.6 * z / (nz * CELL))


def test_density_drop_shrinks_everything_to_zero_before_removal():
    t = particles()
    f = plume_fields()
    for _ in range(12):
        t.advance_frame(f, f, DT)
    start = sizes_by_id(t.snapshot())
    assert len(start) > 100
    step = 0.1 * 0.05
    empty = plume_fields(0.0)
    for k in range(1, 11):
        t.advance_frame(f, empty, DT)
        alive = set(sizes_by_id(t.snapshot()))
        # A particle of size s lives exactly while s - k step > 0 (1e-7: float rounding of s).
        assert {i for i, s in start.items() if s > k * step + 1e-7} <= alive, k
        assert alive <= {i for i, s in start.items() if s > k * step - 1e-7}, k
    assert t.count == 0


def run(threads):
    t = particles(threads=threads, integration=_native.ToonIntegration.MIDPOINT, max_count=300)
    a, b = plume_fields(), plume_fields(0.8, 0.6)
    for f in range(30):
        t.advance_frame(a if f % 2 else b, b if f % 2 else a, 2 * DT, SOURCE,
                        np.array([[0.3, 0.5, 0.2]], np.float32))
    return t.snapshot()


def test_bit_identical_at_one_and_two_threads():
    one, two = run(1), run(2)
    assert len(one["ids"]) > 100
    for key in ("ids", "positions", "velocities", "size", "density", "temperature", "color", "age"):
        assert one[key].tobytes() == two[key].tobytes(), key


def camera_matrix():
    """Camera at (1, -4, 2), turned 30 deg about z then 70 deg about its own x."""
    def rot(axis, deg):
        c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
        i, j = [(1, 2), (2, 0), (0, 1)][axis]
        r = np.eye(4)
        r[i, i] = r[j, j] = c
        r[i, j], r[j, i] = -s, s
        return r
    m = rot(2, 30) @ rot(0, 70)
    m[:3, 3] = (1, -4, 2)
    return m


@pytest.mark.parametrize("perspective", [False, True])
def test_billboard_angle_follows_the_camera_axes(perspective):
    m = camera_matrix()
    right, up, back, loc = m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3]
    p = loc - 5 * back + 0.7 * right - 0.4 * up
    b = _native.toon_billboards(m, perspective, np.array([p, p, p]),
                                np.array([2 * right, 3 * up, np.zeros(3)]), 0.5)
    np.testing.assert_allclose(b["angle"], [0.0, math.pi / 2, 0.0], atol=1e-6)
    np.testing.assert_allclose(b["stretch"], [2.0, 2.5, 1.0], rtol=1e-6)  # 1 + k |v|
    np.testing.assert_allclose(b["axis"][1], up, atol=1e-6)
    with pytest.raises(ValueError, match="4x4"):
        _native.toon_billboards(np.eye(3), True, np.zeros((1, 3)), np.zeros((1, 3)), 1.0)
    t = particles()
    f = plume_fields()
    t.advance_frame(f, f, DT)
    assert len(t.billboards(m)["angle"]) == t.count


def brute_force(z, gamma, dx, dy, ignore, far):
    """§2.2 per pixel, in float32 as the native filter."""
    z = z.astype(np.float32)
    gamma, dx, dy, far = map(np.float32, (gamma, dx, dy, far))
    h, w = z.shape
    out = np.zeros((h, w), np.uint8)
    with np.errstate(invalid="ignore"):
        for j in range(h):
            for i in range(w):
                if ignore and not z[j, i] < far:
                    continue
                for (a, b, d) in ((i + 1, j, dx), (i - 1, j, dx), (i, j + 1, dy), (i, j - 1, dy)):
                    if 0 <= a < w and 0 <= b < h and abs(z[b, a] - z[j, i]) / d > gamma:
                        out[j, i] = 1
    return out


def test_depth_differences_match_the_per_pixel_formula():
    rng = np.random.default_rng(5)
    noise = rng.uniform(1, 3, (23, 41)).astype(np.float32)
    noise[rng.uniform(size=noise.shape) < 0.15] = np.inf
    steps = np.fromfunction(lambda j, i: 1 + 0.25 * ((i // 6) % 4 + (j // 5) % 2), (30, 44),
                            dtype=np.float32).astype(np.float32)
    steps[:8, :9] = 1e10
    for z in (noise, steps):
        for gamma, dx, dy in ((0.3, 1.0, 1.0), (1.1, 0.37, 2.0), (0.0, 1.0, 0.61)):
            for ignore, far in ((False, np.inf), (True, np.inf), (True, 1e9)):
                got = _native.depth_differences(z, gamma, dx, dy, ignore, far)
                assert got.dtype == np.uint8 and got.shape == z.shape
                np.testing.assert_array_equal(got, brute_force(z, gamma, dx, dy, ignore, far))
    with pytest.raises(ValueError, match="gamma"):
        _native.depth_differences(steps, -1.0)
    with pytest.raises(ValueError, match="2-D"):
        _native.depth_differences(np.zeros(4, np.float32), 1.0)


def test_toon_file_round_trip_resume_and_corruption(tmp_path):
    t = particles()
    f = plume_fields()
    for _ in range(5):
        t.advance_frame(f, f, DT, SOURCE)
    path = tmp_path / _native.toon_file_name(5)
    assert path.name == "toon_0005.bin"
    t.write(path)
    snap, read = t.snapshot(), _native.read_toon_file(path)
    for key in snap:
        np.testing.assert_array_equal(np.asarray(read[key]), np.asarray(snap[key]), err_msg=key)
    resumed = particles()
    resumed.load(path)
    resumed.advance_frame(f, f, DT, SOURCE)
    t.advance_frame(f, f, DT, SOURCE)
    assert resumed.snapshot()["positions"].tobytes() == t.snapshot()["positions"].tobytes()
    data = path.read_bytes()
    for bad in (data[:-1], data[:30], data[:100] + bytes([data[100] ^ 1]) + data[101:]):
        path.write_bytes(bad)
        with pytest.raises(RuntimeError, match="toon file"):
            _native.read_toon_file(path)
        with pytest.raises(RuntimeError):
            resumed.load(path)
    with pytest.raises(RuntimeError):
        _native.read_toon_file(tmp_path / "missing.bin")


def baked_volumes(folder):
    """Two Plume volume frames of a small solver run with smoke and a rising flow."""
    p = _native.SmokeParams()
    p.resolution, p.cell_size, p.origin = RES, CELL, ORIGIN
    solver = _native.SmokeSolver(p)
    d = np.zeros(RES, np.float32)
    d[3:7, 3:7, 2:12] = 1.0
    solver.set_density(d)
    nx, ny, nz = RES
    solver.set_velocity(np.zeros((nx + 1, ny, nz), np.float32), np.zeros((nx, ny + 1, nz), np.float32),
                        np.full((nx, ny, nz + 1), 0.8, np.float32))
    paths = []
    for n in range(2):
        path = folder / f"volume_{n + 1:04d}.vdb"
        solver.write_vdb(str(path))
        paths.append(path)
        solver.step(DT)
    return paths


def test_advance_from_plume_volume_files(tmp_path):
    a, b = baked_volumes(tmp_path)
    t = particles()
    assert t.advance_frame_from_vdb(a, b, DT, SOURCE) >= 1
    ref = particles()
    fa = _native.ToonFields.from_vdb(a, RES, ORIGIN, CELL)
    fb = _native.ToonFields.from_vdb(b, RES, ORIGIN, CELL)
    assert fa.resolution == RES and fa.max_speed() > 0.5
    ref.advance_frame(fa, fb, DT, SOURCE)
    assert t.count > 100  # the dense block of 160 cells is filled
    assert t.snapshot()["positions"].tobytes() == ref.snapshot()["positions"].tobytes()
    with pytest.raises(RuntimeError, match="missing"):
        t.advance_frame_from_vdb(b, tmp_path / "missing.vdb", DT)
    with pytest.raises(RuntimeError, match="cell size"):
        _native.ToonFields.from_vdb(a, RES, ORIGIN, 0.2)
