"""The flow graph from Python ([Graph Fire Synthesis] §4.3-5.1): cost_matrix against
NumPy's eq. 9-10, FlowGraph.build (no dead ends, at most M² transitions, ε checks), RandomWalk
(seeded, target states) and the Figure 4 picture, plus the errors on bad input."""
import numpy as np
import pytest

import _native

P, L, DT = 20, 6, 1.0 / 48.0


def groups(counts=(40, 32), particles=P, seed=0):
    """One source field oscillating with period 9 + 4 s in state s, plus noise: recurrences
    inside a state and similar nodes across states, for transitions to connect."""
    rng = np.random.default_rng(seed)
    out = []
    base = rng.random((particles, L, 5)).astype(np.float32)
    for state, count in enumerate(counts):
        for step in range(count):
            wave = 1 + 0.3 * np.sin(2 * np.pi * step / (9 + 4 * state))
            f = (base * wave + 0.02 * rng.random(base.shape)).astype(np.float32)
            out.append(_native.PathlineGroup(
                start=np.zeros((particles, 3), np.float32), velocity=f[..., :3], density=f[..., 3],
                temperature=f[..., 4], sample_dt=DT, state=state, step=step))
    return out


def brute_cost(a, b, alpha, beta):
    """Eq. 9-10 in float64: rectangle rule over the L samples, mean over the particles."""
    du = np.sum((a.velocity.astype(np.float64) - b.velocity) ** 2, axis=(0, 2))
    dr = np.sum((a.density.astype(np.float64) - b.density) ** 2, axis=0)
    dt = np.sum((a.temperature.astype(np.float64) - b.temperature) ** 2, axis=0)
    n = a.layout.particles
    return np.sqrt(np.sum(DT * (du / n + alpha * dr / n + beta * dt / n)))


def params(**kw):
    p = _native.FlowGraphParams()
    p.alpha, p.beta, p.block_size = 0.5, 2.0, 8
    for k, v in kw.items():
        setattr(p, k, v)
    return p


@pytest.fixture(scope="module")
def data():
    g = groups()
    cost = _native.cost_matrix(g, params())
    return g, cost


def test_cost_matrix_matches_numpy(data):
    g, cost = data
    assert cost.shape == (72, 72) and cost.dtype == np.float64
    np.testing.assert_array_equal(cost, cost.T)
    np.testing.assert_array_equal(np.diag(cost), 0.0)
    for i, j in [(0, 1), (3, 50), (71, 0), (39, 40), (10, 19)]:
        # Float sums of float squares, double across chunks: 1e-5 relative (see the C++ test).
        assert cost[i, j] == pytest.approx(brute_cost(g[i], g[j], 0.5, 2.0), rel=1e-5)


def test_same_magnitude_weights_are_positive(data):
    alpha, beta = _native.same_magnitude_weights(data[0])
    assert alpha > 0 and beta > 0


def test_graph_has_no_dead_end_and_at_most_m_squared_transitions(data):
    _, cost = data
    graph = _native.FlowGraph.build(cost, [40, 32], params())
    assert graph.node_count == 72 and graph.state_count == 2
    assert graph.state_node_counts == [40, 32]
    pruned = graph.pruned
    assert sum(graph.pruned_per_state) == int(pruned.sum())
    for n in range(72):
        assert (graph.out_degree(n) == 0) == pruned[n]
    e = graph.edges()
    assert not pruned[e["to"]].any()
    assert np.all(e["to"][e["temporal"]] == e["from"][e["temporal"]] + 1)
    t = graph.transitions()
    m = t["blocks_per_side"]
    assert m == 9 and len(t["row"]) <= m * m and t["kept"].sum() <= m * m
    assert t["epsilon"] == pytest.approx((2 * t["a"] + t["b"]) / 3)
    assert np.all(t["kept"] == (t["cost"] < t["epsilon"]))


def test_bad_inputs_raise_value_error(data):
    g, cost = data
    with pytest.raises(ValueError, match="block_size"):
        params(block_size=0).validate()
    with pytest.raises(ValueError, match="block_size"):
        _native.FlowGraph.build(cost, [40, 32], params(block_size=0))
    t = _native.FlowGraph.build(cost, [40, 32], params()).transitions()
    with pytest.raises(ValueError, match=r"epsilon must be in \[a, b\]"):
        _native.FlowGraph.build(cost, [40, 32], params(epsilon_mode=_native.EpsilonMode.EXPLICIT,
                                                       epsilon=t["b"] * 2))
    with pytest.raises(ValueError, match="symmetric"):
        bad = cost.copy()
        bad[0, 1] += 1
        _native.FlowGraph.build(bad, [40, 32], params())
    with pytest.raises(ValueError, match="add up to"):
        _native.FlowGraph.build(cost, [40, 30], params())
    other = groups(counts=(2,), particles=P + 1)
    for grp in other:
        grp.state = 1
    with pytest.raises(ValueError, match="state 1 has 21 particles per group, state 0 has 20"):
        _native.cost_matrix(g[:3] + other, params())
    with pytest.raises(ValueError, match="PathlineGroup"):
        _native.cost_matrix([1, 2], params())


def test_walks_are_seeded_and_reach_their_target(data):
    _, cost = data
    graph = _native.FlowGraph.build(cost, [40, 32], params())
    targets = np.array([-1] * 200 + [1] * 400 + [0] * 400)
    a = _native.RandomWalk(graph, 7, _native.WalkBias.TEMPORAL, 0.875).run(targets)
    b = _native.RandomWalk(graph, 7, _native.WalkBias.TEMPORAL, 0.875).run(targets)
    np.testing.assert_array_equal(a, b)
    states = graph.node_states[a]
    for target, first, last in [(1, 200, 600), (0, 600, 1000)]:
        hits = np.flatnonzero(states[first:last] == target)
        assert hits.size, f"state {target} never reached"
        assert np.all(states[first + hits[0]:last] == target), "left the target state"
    walk = _native.RandomWalk(graph, 1)
    p = walk.edge_probabilities(walk.current)
    assert p.sum() == pytest.approx(1.0) and len(p) == graph.out_degree(walk.current)
    with pytest.raises(ValueError, match="gamma"):
        _native.RandomWalk(graph, 1, _native.WalkBias.TEMPORAL, 2.0)
    with pytest.raises(ValueError, match="target_state"):
        walk.next(5)


def test_transition_hold_from_python(data):
    """The transition state through the binding: a held walk keeps its transitions more than H
    steps apart (the C++ tests check it at 10^5 steps), and a hold no state can keep is refused."""
    _, cost = data
    graph = _native.FlowGraph.build(cost, [40, 32], params())
    walk = _native.RandomWalk(graph, 3, _native.WalkBias.UNIFORM, transition_hold=8)
    assert walk.transition_hold == 8 and walk.hold_remaining == 0
    nodes = np.concatenate([[walk.current], walk.run(np.full(3000, -1))])
    states, steps = graph.node_states[nodes], graph.node_steps[nodes]
    jumps = np.flatnonzero((states[1:] != states[:-1]) | (steps[1:] != steps[:-1] + 1))
    assert jumps.size > 20 and np.diff(jumps).min() > 8
    assert walk.temporal_run(0) >= 8
    with pytest.raises(ValueError, match=r"transition_hold must be in \[0, 31\]"):
        _native.RandomWalk(graph, 1, transition_hold=32)
    with pytest.raises(ValueError, match="node"):
        walk.temporal_run(72)


def test_cost_matrix_image(data):
    _, cost = data
    graph = _native.FlowGraph.build(cost, [40, 32], params())
    img = _native.cost_matrix_image(cost, graph, 144)
    assert img.shape == (144, 144, 3) and img.dtype == np.uint8
    t = graph.transitions()
    r, c = t["row"][t["kept"]][0], t["col"][t["kept"]][0]
    assert tuple(img[2 * r + 1, 2 * c + 1]) == (255, 220, 0)  # a yellow mark on a kept edge
    with pytest.raises(ValueError, match="size"):
        _native.cost_matrix_image(cost, graph, 0)


def test_cost_matrix_job_runs_and_cancels(data):
    g, cost = data
    job = _native.CostMatrixJob(g, params())
    assert job.progress == 0.0
    with pytest.raises(ValueError, match="not computed"):
        job.cost
    assert job.run() is True
    assert job.progress == 1.0
    np.testing.assert_array_equal(job.cost, cost)  # same bits as cost_matrix()
    cancelled = _native.CostMatrixJob(g, params())
    cancelled.cancel()
    assert cancelled.run() is False
    with pytest.raises(ValueError, match="not computed"):
        cancelled.cost


def test_reachable_states(data):
    _, cost = data
    graph = _native.FlowGraph.build(cost, [40, 32], params())
    assert graph.reachable_states(0) == [0, 1]
    with pytest.raises(ValueError, match="state"):
        graph.reachable_states(2)
    with pytest.raises(ValueError, match="node"):
        graph.out_degree(72)


def test_streamed_cost_matrix_is_the_in_memory_one_bit_for_bit(tmp_path):
    """The add-on's build streams the groups from the states' pathline files: the same C and
    weights α, β, bit for bit, as with every group read into memory, at 1 and 2 threads."""
    from test_flowgraph_synth import recorded_bake
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    path_a, _, _ = recorded_bake(tmp_path / "a", frames=24)
    path_b, _, _ = recorded_bake(tmp_path / "b", frames=20, float16=True)
    files = [_native.PathlineFile.open(path_a), _native.PathlineFile.open(path_b)]
    groups = [f.read_group(k, s) for s, f in enumerate(files) for k in range(f.node_count)]
    assert len(groups) == 38 + 30  # three tiles of 32 per side
    alpha, beta = _native.same_magnitude_weights(groups)
    assert _native.same_magnitude_weights_of_files(files, threads=1) == (alpha, beta)
    assert _native.same_magnitude_weights_of_files(files, threads=2) == (alpha, beta)
    p = params(alpha=alpha, beta=beta)
    memory = _native.cost_matrix(groups, p)
    for threads in (1, 2):
        p.threads = threads
        # 1 MB rows: the smallest row block (32 nodes), so rows and columns are both streamed.
        streamed, stats = _native.cost_matrix_of_files(files, p, row_block_mb=1, column_nodes=32)
        np.testing.assert_array_equal(streamed, memory)
        assert stats["row_nodes"] == 32 and stats["group_reads"] == 68 + 36 + 4
        job = _native.CostMatrixJob.of_files(files, p)
        assert job.run() is True and job.progress == 1.0
        np.testing.assert_array_equal(job.cost, memory)
        assert job.stats["group_reads"] == 68  # one row block holds all: each group read once
    cancelled = _native.CostMatrixJob.of_files(files, p)
    cancelled.cancel()
    assert cancelled.run() is False
    with pytest.raises(ValueError, match="not a PathlineFile"):
        _native.cost_matrix_of_files([files[0], groups[0]], p)
    with pytest.raises(ValueError, match="row_block_mb"):
        _native.cost_matrix_of_files(files, p, row_block_mb=0)
