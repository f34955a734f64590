"""Streaklines and streak surfaces from Python (smoke_surfaces §3.2-3.3): point sources, the
tracer driven by the solver, streak files, distances h, threshold h0, clusters and ordering."""
import itertools
import threading
import time

import numpy as np
import pytest

import _native
from meshes import box_mesh


def small_params(**overrides):
    p = _native.SmokeParams(resolution=(16, 16, 20), cell_size=1.0 / 16)
    for key, value in overrides.items():
        setattr(p, key, value)
    return p


def streaking_solver(params, points_per_cell=3, emission_period=1):
    """Solver with a box source and a tracer whose point sources fill the source cells."""
    solver = _native.SmokeSolver(params)
    vertices, triangles = box_mesh((0.4, 0.4, 0.05), (0.6, 0.6, 0.2))
    settings = _native.SourceSettings()
    settings.velocity = (0.0, 0.0, 0.5)
    cells, motion = _native.source_cells(vertices, triangles, np.eye(4), np.eye(4), params, "src")
    assert solver.add_source(vertices, triangles, np.eye(4), np.eye(4), settings, "src") == len(cells)
    points = _native.random_points_in_cells(cells, params.resolution, params.cell_size,
                                            params.origin, points_per_cell, params.seed)
    velocities = np.repeat(motion, points_per_cell, axis=0) + np.asarray(settings.velocity)
    tracer = _native.StreakTracer(params, emission_period=emission_period)
    assert tracer.add_point_sources(points, np.zeros(len(points), int), velocities) == 0
    return solver, tracer, points


# --- point sources ---------------------------------------------------------------------------

def test_random_points_lie_in_their_cells_and_are_deterministic():
    res, h, origin = (6, 5, 4), 0.2, (-1.0, 0.5, 2.0)
    cells = np.array([0, 13, 119], dtype=np.uint32)
    p = _native.random_points_in_cells(cells, res, h, origin, 12, seed=5, stream=2)
    assert p.shape == (36, 3) and p.dtype == np.float32
    c = np.repeat(cells, 12)
    corner = np.stack([c % 6, (c // 6) % 5, c // 30], axis=1) * h + np.asarray(origin)
    local = (p - corner) / h
    assert local.min() >= -1e-5 and local.max() <= 1 + 1e-5
    np.testing.assert_array_equal(p, _native.random_points_in_cells(cells, res, h, origin, 12, 5, 2))
    assert not np.array_equal(p, _native.random_points_in_cells(cells, res, h, origin, 12, 5, 3))
    with pytest.raises(ValueError, match="point_sources"):
        _native.random_points_in_cells(cells, res, h, origin, 0, 5)
    with pytest.raises(ValueError, match="outside the grid"):
        _native.random_points_in_cells([120], res, h, origin, 3, 5)


# --- tracer ----------------------------------------------------------------------------------

def uniform_velocity(n, v):
    nx, ny, nz = n
    return (np.full((nx + 1, ny, nz), v[0], np.float32), np.full((nx, ny + 1, nz), v[1], np.float32),
            np.full((nx, ny, nz + 1), v[2], np.float32))


def test_tracer_step_moves_particles_exactly_in_a_uniform_field():
    p = small_params(interpolation=_native.Interpolation.LINEAR)
    tracer = _native.StreakTracer(p, emission_period=2)
    assert tracer.interpolation == _native.Interpolation.LINEAR
    assert tracer.emission_period == 2
    source = np.array([[0.3, 0.5, 0.2], [0.6, 0.4, 0.3]], np.float32)
    tracer.add_point_sources(source, [0, 1])
    v = (0.2, -0.1, 0.4)
    vel = uniform_velocity(p.resolution, v)
    density = np.full(p.resolution, 0.25, np.float32)
    dt = 0.05
    for _ in range(5):
        tracer.step(vel, vel, density, dt)
    snap = tracer.snapshot()
    assert tracer.steps == 5 and tracer.particles_per_source == 5 // 2 + 1
    np.testing.assert_array_equal(snap["counts"], [3, 3])
    np.testing.assert_array_equal(snap["groups"], [0, 1])
    assert snap["positions"].shape == (6, 3) and snap["density"].shape == (6,)
    # Emitted at steps 0, 2, 4: travelled 5, 3, 1 steps.
    for s in range(2):
        for e, travelled in enumerate([5, 3, 1]):
            expected = source[s] + np.asarray(v) * dt * travelled
            np.testing.assert_allclose(snap["positions"][3 * s + e], expected, atol=1e-5)
    np.testing.assert_allclose(snap["density"], 0.25)
    assert not snap["outside"].any()


def test_tracer_rejects_bad_input():
    p = small_params()
    with pytest.raises(ValueError, match="emission_period"):
        _native.StreakTracer(p, emission_period=0)
    tracer = _native.StreakTracer(p)
    with pytest.raises(ValueError, match="outside the domain"):
        tracer.add_point_sources([[5.0, 0.5, 0.5]], [0])
    with pytest.raises(ValueError):
        tracer.add_point_sources([[0.5, 0.5, 0.5]], [0, 1])
    tracer.add_point_sources([[0.5, 0.5, 0.5]], [0])
    vel = uniform_velocity(p.resolution, (0, 0, 0))
    with pytest.raises(ValueError, match="density must have shape"):
        tracer.step(vel, vel, np.zeros((3, 3, 3), np.float32), 0.1)
    tracer.step(vel, vel, np.zeros(p.resolution, np.float32), 0.1)
    with pytest.raises(ValueError, match="before the first step"):
        tracer.add_point_sources([[0.5, 0.5, 0.5]], [0])


def test_advance_frame_with_tracers_matches_advance_frame():
    p = small_params()
    plain, _, _ = streaking_solver(p)
    solver, tracer, points = streaking_solver(p)
    for frame in range(3):
        assert plain.advance_frame() is True
        assert _native.advance_frame_with_tracers(solver, tracer) is True
    assert solver.frame == 3
    np.testing.assert_array_equal(plain.get_density(), solver.get_density())
    snap = tracer.snapshot()
    n = len(points)
    assert snap["counts"].tolist() == [tracer.steps + 1] * n
    assert snap["positions"].shape == (n * (tracer.steps + 1), 3)
    # Youngest particle of each streakline sits at its source; the oldest has risen.
    per = tracer.steps + 1
    np.testing.assert_array_equal(snap["positions"][per - 1::per], points)
    assert (snap["positions"][0::per, 2] - points[:, 2]).mean() > 0.03
    assert snap["density"].max() > 0


def test_tracer_cancel_and_gil_release():
    p = small_params(resolution=(32, 32, 32), cell_size=1.0 / 32, substeps=400)
    solver, tracer, _ = streaking_solver(p)
    tracer.cancel()
    assert _native.advance_frame_with_tracers(solver, tracer) is False
    assert solver.frame == 0
    result = {}
    worker = threading.Thread(
        target=lambda: result.setdefault("ok", _native.advance_frame_with_tracers(solver, tracer)))
    start = time.monotonic()
    worker.start()
    ticks = 0
    # The GIL is released: this thread keeps running and cancels through the tracer.
    while worker.is_alive():
        ticks += 1
        tracer.cancel()
        worker.join(0.01)
    assert result["ok"] is False
    assert time.monotonic() - start < 30.0
    solver.cancel()  # the solver's own cancel stops a traced frame too
    assert _native.advance_frame_with_tracers(solver, tracer) is False


def test_tracer_checkpoint_resumes_bit_for_bit_with_the_solver(tmp_path):
    p = small_params()
    solver, tracer, _ = streaking_solver(p, emission_period=2)
    for _ in range(2):
        assert _native.advance_frame_with_tracers(solver, tracer)
    solver.save_state(tmp_path / "state.bin")
    tracer.save_state(tmp_path / "tracer_state.bin", frame=2)
    for _ in range(2):
        assert _native.advance_frame_with_tracers(solver, tracer)
    straight = tracer.snapshot()

    solver2, tracer2, _ = streaking_solver(p, emission_period=2)
    solver2.load_state(tmp_path / "state.bin")
    assert tracer2.load_state(tmp_path / "tracer_state.bin") == 2
    for _ in range(2):
        assert _native.advance_frame_with_tracers(solver2, tracer2)
    resumed = tracer2.snapshot()
    assert tracer2.steps == tracer.steps
    for key in ("counts", "positions", "density", "groups", "outside"):
        assert resumed[key].tobytes() == straight[key].tobytes(), key

    # Bad files raise RuntimeError naming the path and leave the tracer as it was.
    data = (tmp_path / "tracer_state.bin").read_bytes()
    bad = tmp_path / "bad.bin"
    before = tracer2.snapshot()
    for content in (data[:len(data) // 2], data[:-1] + bytes([data[-1] ^ 1]), b""):
        bad.write_bytes(content)
        with pytest.raises(RuntimeError, match="bad.bin"):
            tracer2.load_state(bad)
        assert tracer2.snapshot()["positions"].tobytes() == before["positions"].tobytes()
    with pytest.raises(RuntimeError, match="emission_period 2"):
        _native.StreakTracer(p, emission_period=1).load_state(tmp_path / "tracer_state.bin")
    with pytest.raises(RuntimeError, match="cannot be written"):
        tracer.save_state(tmp_path / "missing" / "t.bin", frame=1)


def test_tracer_emission_pause_with_the_solver(tmp_path):
    # Figure 10: emission off for some frames leaves a gap; the particles already out keep moving.
    p = small_params()
    solver, tracer, _ = streaking_solver(p)
    assert tracer.emitting
    assert _native.advance_frame_with_tracers(solver, tracer)
    rows = tracer.particles_per_source
    assert rows == tracer.steps + 1  # one row per step, and the first
    tracer.emitting = False
    before, steps = tracer.snapshot()["positions"], tracer.steps
    assert _native.advance_frame_with_tracers(solver, tracer)
    assert tracer.steps > steps and tracer.particles_per_source == rows
    assert not np.array_equal(tracer.snapshot()["positions"], before)  # they moved
    tracer.save_state(tmp_path / "paused.bin", frame=2)
    _, restored, _ = streaking_solver(p)
    restored.load_state(tmp_path / "paused.bin")
    assert not restored.emitting  # the switch is part of the checkpoint
    tracer.emitting = True
    paused_steps = tracer.steps
    assert _native.advance_frame_with_tracers(solver, tracer)
    assert tracer.particles_per_source == rows + (tracer.steps - paused_steps)


# --- streak files ----------------------------------------------------------------------------

def test_streak_file_round_trip_and_errors(tmp_path):
    p = small_params()
    solver, tracer, _ = streaking_solver(p, points_per_cell=1)
    assert _native.advance_frame_with_tracers(solver, tracer)
    snap = tracer.snapshot()
    path = tmp_path / _native.streak_file_name(1)
    assert path.name == "streaks_0001.bin"
    _native.write_streak_file(path, snap)
    back = _native.read_streak_file(path)
    for key in ("counts", "positions", "density", "groups", "outside"):
        np.testing.assert_array_equal(back[key], snap[key])
    # Truncated and corrupt files raise RuntimeError naming the path.
    data = path.read_bytes()
    bad = tmp_path / "streaks_0002.bin"
    bad.write_bytes(data[:-3])
    with pytest.raises(RuntimeError, match="streaks_0002.bin"):
        _native.read_streak_file(bad)
    flipped = bytearray(data)
    flipped[len(data) // 2] ^= 1
    bad.write_bytes(bytes(flipped))
    with pytest.raises(RuntimeError, match="corrupt"):
        _native.read_streak_file(bad)
    with pytest.raises(RuntimeError, match="cannot be written"):
        _native.write_streak_file(tmp_path / "missing" / "s.bin", snap)
    with pytest.raises(ValueError):
        _native.write_streak_file(path, {"counts": [2], "positions": np.zeros((3, 3)),
                                         "density": np.zeros(3)})
    with pytest.raises(ValueError, match="density"):
        _native.write_streak_file(path, {"counts": [1], "positions": np.zeros((1, 3))})


# --- distances, clusters, order --------------------------------------------------------------

def random_snapshots(sources, counts, seed):
    rng = np.random.default_rng(seed)
    # float32, as the core stores positions, so that the brute force sees the same numbers.
    return [{"counts": np.full(sources, n),
             "positions": (rng.normal(size=(sources * n, 3)) +
                           np.repeat(np.arange(sources), n)[:, None] * [0.3, 0, 0]).astype(np.float32)}
            for n in counts]


def brute_h(snaps, a, b):
    total = 0.0
    for s in snaps:
        n = int(s["counts"][a])
        if n == 0:
            continue
        pa = np.asarray(s["positions"], np.float64)[a * n:(a + 1) * n]
        pb = np.asarray(s["positions"], np.float64)[b * n:(b + 1) * n]
        total += ((pa - pb) ** 2).sum() / n
    return total


def brute_clusters(h, h0):
    n = len(h)
    parent = list(range(n))

    def find(x):
        while parent[x] != x:
            x = parent[x]
        return x

    for a, b in itertools.combinations(range(n), 2):
        if h[a, b] < h0:
            ra, rb = find(a), find(b)
            parent[max(ra, rb)] = min(ra, rb)
    groups = {}
    for a in range(n):
        groups.setdefault(find(a), []).append(a)
    return sorted((g for g in groups.values() if len(g) >= 2), key=lambda g: g[0])


def brute_order(h, members):
    """§3.3 Figure 5 over the full matrix: closest pair first, then the member closest to
    either end (ties: earlier member, front end)."""
    pos = list(members)
    best = min(((h[pos[a], pos[b]], a, b) for a in range(len(pos)) for b in range(a + 1, len(pos))))
    front, chain = [], [pos[best[1]], pos[best[2]]]
    rest = [m for k, m in enumerate(pos) if k not in (best[1], best[2])]
    while rest:
        head = front[-1] if front else chain[0]
        tail = chain[-1]
        cands = [(h[r, head], k, 0) for k, r in enumerate(rest)] + \
                [(h[r, tail], k, 1) for k, r in enumerate(rest)]
        _, k, end = min(cands)
        (front if end == 0 else chain).append(rest.pop(k))
    return front[::-1] + chain


def brute_matrix(snaps, ids):
    """h for every pair of ids, in float64 numpy (the paper's formula)."""
    n = len(ids)
    h = np.zeros((n, n))
    for s in snaps:
        counts = np.asarray(s["counts"])
        N = int(counts[ids[0]]) if n else 0
        if N == 0:
            continue
        offsets = np.concatenate([[0], np.cumsum(counts)])
        pos = np.asarray(s["positions"], np.float64)
        lines = np.stack([pos[offsets[i]:offsets[i] + N].ravel() for i in ids])
        sq = (lines ** 2).sum(1)
        h += np.maximum(sq[:, None] + sq[None, :] - 2 * lines @ lines.T, 0) / N
    np.fill_diagonal(h, 0.0)
    return h


def midpoints(values):
    """Thresholds between consecutive distinct values: decided the same way by any rounding."""
    v = np.unique(values)
    return list((v[:-1] + v[1:]) / 2)


@pytest.mark.parametrize("sources,counts", [(2, [1]), (4, [0, 2, 5, 1]), (9, [3, 0, 7, 7, 12])])
def test_distances_threshold_and_clusters_match_brute_force(sources, counts):
    snaps = random_snapshots(sources, counts, seed=sources)
    ids = list(range(sources))[::-1]
    expected = np.zeros((sources, sources))
    for a, b in itertools.combinations(range(sources), 2):
        expected[a, b] = expected[b, a] = brute_h(snaps, ids[a], ids[b])
    upper = expected[np.triu_indices(sources, 1)]
    # Every pair (reach = inf): the same h as the formula, sorted by (a, b).
    full = _native.streak_distances(snaps, ids, reach=np.inf)
    assert len(full) == full.size == sources and full.pair_count == len(upper)
    a, b, h = full.pairs()
    assert h.dtype == np.float64 and a.dtype == np.int32
    np.testing.assert_array_equal(np.stack([a, b]), np.triu_indices(sources, 1))
    np.testing.assert_allclose(h, expected[a, b], rtol=1e-12, atol=1e-12)
    last = np.flatnonzero((a == 0) & (b == sources - 1))[0]
    assert full.distance(0, sources - 1) == full.distance(sources - 1, 0) == h[last]  # bit for bit
    # The default: h0 = the mean of h, every pair below it held and no other.
    d = _native.streak_distances(snaps, ids)
    assert _native.default_threshold(d) == pytest.approx(upper.mean(), rel=1e-12)
    assert d.mean == d.reach == _native.default_threshold(d)
    a, b, h = d.pairs()
    assert set(zip(a.tolist(), b.tolist())) == {(x, y) for x, y in zip(*np.triu_indices(sources, 1))
                                                if expected[x, y] < d.mean}
    for h0 in [0.0, *np.quantile(upper, [0.2, 0.5, 0.8]), _native.default_threshold(d), 2 * upper.max()]:
        dist = d if h0 <= d.reach else full
        clusters = _native.cluster_sources(dist, h0)
        assert clusters == brute_clusters(expected, h0)
        assert _native.cluster_summary(dist, h0) == (len(clusters), sum(map(len, clusters)))
        for c in clusters:
            assert _native.order_greedy(dist, c) == brute_order(expected, c)


def test_order_greedy_recovers_shuffled_parallel_streaklines():
    rng = np.random.default_rng(3)
    n, frames = 11, 8
    slot = rng.permutation(n)
    snaps = []
    for t in range(frames):
        k = t + 1
        heights = 0.1 * np.arange(k, 0, -1)
        pos = [[slot[s] * 0.05, 0.0, z] for s in range(n) for z in heights]
        snaps.append({"counts": np.full(n, k), "positions": np.array(pos, np.float32)})
    h = _native.streak_distances(snaps, np.arange(n))
    order = _native.order_greedy(h, list(range(n)))
    slots = [int(slot[m]) for m in order]
    assert slots in (list(range(n)), list(range(n))[::-1])
    surfaces = _native.build_surfaces(snaps, np.zeros(n, int), 1e9)
    assert len(surfaces) == 1 and surfaces[0]["group"] == 0
    assert [int(slot[s]) for s in surfaces[0]["sources"]] in (list(range(n)), list(range(n))[::-1])


def test_clustering_errors():
    snaps = random_snapshots(3, [2, 3], seed=1)
    d = _native.streak_distances(snaps, [0, 1])
    with pytest.raises(ValueError, match="h0"):
        _native.cluster_sources(d, -1.0)
    with pytest.raises(ValueError, match="above the reach"):
        _native.cluster_summary(d, 2 * d.reach + 1.0)
    with pytest.raises(TypeError):
        _native.cluster_summary(np.zeros((2, 3)), 1.0)  # distances come from streak_distances
    with pytest.raises(ValueError, match="at least 2"):
        _native.streak_distances(snaps, [0])
    with pytest.raises(ValueError, match="repeats"):
        _native.order_greedy(d, [1, 1])
    with pytest.raises(ValueError, match="not in h"):
        _native.order_greedy(d, [0, 2])
    with pytest.raises(IndexError):
        d.distance(0, 2)
    with pytest.raises(ValueError, match="reach"):
        d.with_reach(-1.0)
    with pytest.raises(ValueError, match="candidate group 5"):
        _native.build_surfaces(snaps, [0, 0, 5])
    with pytest.raises(ValueError, match="not in frame"):
        _native.streak_distances(snaps, [0, 3])
    snaps[1]["counts"] = np.array([3, 2, 4])
    with pytest.raises(ValueError, match="equal counts"):
        _native.streak_distances(snaps, [0, 1])
    with pytest.raises(ValueError, match="snapshot 1"):
        _native.StreakFrames([snaps[0], {"counts": [2], "positions": np.zeros((3, 3))}])


def test_surfaces_from_a_baked_plume(tmp_path):
    """End to end: bake with tracers, write and read the streak files, cluster the sources."""
    p = small_params()
    solver, tracer, points = streaking_solver(p, points_per_cell=2)
    paths = []
    for frame in range(1, 5):
        assert _native.advance_frame_with_tracers(solver, tracer)
        paths.append(tmp_path / _native.streak_file_name(frame))
        _native.write_streak_file(paths[-1], tracer.snapshot())
    snaps = [_native.read_streak_file(path) for path in paths]
    surfaces = _native.build_surfaces(snaps)
    used = [s for surface in surfaces for s in surface["sources"]]
    assert len(used) == len(set(used)) and all(len(s["sources"]) >= 2 for s in surfaces)
    h = _native.streak_distances(snaps, np.arange(len(points)))
    assert _native.cluster_summary(h, _native.default_threshold(h)) == (
        len(surfaces), len(used))
    # The Figure 4 curve gives the same counts as the clusters, at every step.
    values, n_surfaces, n_lines = h.curve()
    for v, s, n in zip(values, n_surfaces, n_lines):
        h0 = float(np.nextafter(v, np.inf))
        if h0 <= h.reach:
            clusters = _native.cluster_sources(h, h0)
            assert (s, n) == (len(clusters), sum(map(len, clusters)))


def exact_matrix(snaps, ids):
    """h for every pair by direct differences in float64 (no cancellation), row blocks."""
    lines = []
    for s in snaps:
        counts = np.asarray(s["counts"])
        N = int(counts[ids[0]])
        if N == 0:
            continue
        offsets = np.concatenate([[0], np.cumsum(counts)])
        pos = np.asarray(s["positions"], np.float64)
        lines.append(np.stack([pos[offsets[i]:offsets[i] + N].ravel() for i in ids]) / np.sqrt(N))
    x = np.concatenate(lines, axis=1)
    h = np.empty((len(ids), len(ids)))
    for r in range(0, len(ids), 64):
        h[r:r + 64] = ((x[r:r + 64, None, :] - x[None, :, :]) ** 2).sum(-1)
    return h


def test_sparse_clustering_of_a_baked_plume_equals_brute_force():
    """A real bake with hundreds of point sources (the pruning directions in use): the held pairs,
    default h0, clusters, counts and greedy orders equal a brute force over all pairs."""
    p = small_params()
    solver, tracer, points = streaking_solver(p, points_per_cell=32)
    snaps = []
    for frame in range(6):
        assert _native.advance_frame_with_tracers(solver, tracer)
        snaps.append(tracer.snapshot())
    n = len(points)
    assert n >= 512  # StreakDistances finds pruning directions from 512 members on
    ids = np.arange(n)
    h = _native.streak_distances(_native.StreakFrames(snaps), ids)
    full = exact_matrix(snaps, ids)
    upper = full[np.triu_indices(n, 1)]
    assert h.mean == pytest.approx(upper.mean(), rel=1e-12)
    a, b, held = h.pairs()
    np.testing.assert_allclose(held, full[a, b], rtol=1e-12)
    near = np.abs(upper / h.reach - 1) < 1e-9  # too close to the reach for numpy's rounding
    expected = (upper < h.reach) & ~near
    got = np.zeros((n, n), bool)
    got[a, b] = True
    assert np.array_equal(got[np.triu_indices(n, 1)] & ~near, expected)
    # Most pairs lie below the mean on a plume (one big surface); of the others, the projection
    # bound rules out nearly all without computing h.
    assert h.stats["exact"] - h.stats["kept"] < 0.05 * (len(upper) - h.stats["kept"]), h.stats
    print(f"  {n} sources: {h.pair_count} pairs below the mean of {len(upper)}, {h.stats}")
    # At a threshold giving small surfaces the grid looks at a small share of the pairs, and the
    # narrower distances still equal the brute force.
    narrow = h.with_reach(float(np.quantile(held, 0.01)))
    print(f"  reach at 1 % of the held pairs: {narrow.stats}")
    assert narrow.stats["examined"] < 0.25 * len(upper), narrow.stats
    a, b, _ = narrow.pairs()
    assert set(zip(a.tolist(), b.tolist())) == {
        (x, y) for x, y in zip(*np.triu_indices(n, 1)) if full[x, y] < narrow.reach}
    thresholds = midpoints(np.quantile(held, [0.001, 0.01, 0.05, 0.2, 0.6, 0.95]))
    for h0 in thresholds + [h.reach]:
        clusters = _native.cluster_sources(h, h0)
        assert clusters == brute_clusters(full, h0), h0
        assert _native.cluster_summary(h, h0) == (len(clusters), sum(map(len, clusters)))
        for c in clusters:
            if len(c) <= 40:
                assert _native.order_greedy(h, c) == brute_order(full, c), (h0, c)
    # An order far beyond the reach: h computed on demand for the pairs not held.
    some = list(np.random.default_rng(4).choice(n, 30, replace=False))
    assert _native.order_greedy(h, some) == brute_order(full, some)
    # build_surfaces is the same path end to end.
    surfaces = _native.build_surfaces(snaps, None, float(thresholds[1]))
    assert [s["sources"] for s in surfaces] == [
        _native.order_greedy(h, c) for c in _native.cluster_sources(h, thresholds[1])]
