"""Streak surfaces from Python (smoke_surfaces §3.3): distances h, threshold h0, clusters and
ordering, checked against brute force, on random snapshots and on a baked plume."""
import itertools

import numpy as np
import pytest

import _native
from streak_scenes import small_params, streaking_solver


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
