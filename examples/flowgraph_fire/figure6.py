"""Figure 6 of [Graph Fire Synthesis] as numbers: how the traversal strategy (§5.1) and the
block size B (§4.3) shape a synthesized fire's walk, on a real flow graph.

    /usr/bin/python3 examples/flowgraph_fire/figure6.py OUT_DIR GRAPH_NPZ [NATIVE_DIR]

GRAPH_NPZ is the flowgraph.npz Build Flow Graph wrote (e.g. the campfire example's, in
OUT_DIR/plume_cache/State0 Calm/ after examples/flowgraph_fire/campfire.py); it holds the cost
matrix, so graphs of other block sizes are built from the same costs (ε = (2a + b)/3 each, a and b
over the candidates that are not hops between states at the same moment, as Build Flow Graph
takes them: flowgraph.threshold, written out here to run without Blender).
NATIVE_DIR holds _native*.so (default: build/native of this repository).

For B in {1, 8, 32} and the strategies of §5.1 — random (p = 1/d), temporal bias γ = 0.875
(eq. 12), and target states (the target switching state every 20 frames) — each without and
with the transition state (the hold of §5: temporal edges only for the pathlines' lifetime L
after a transition), a seeded walk of 50,000 node steps gives:
  - the share of temporal edges taken (the paper: a higher γ gives "more stable states"),
  - the mean time between transitions, in frames,
  - the mean cost c_ij of the transitions taken (lower: smoother transitions; the paper: "temporal
    bias and a larger block size B produce smoother transitions").
Prints a table and writes OUT_DIR/figure6.png (three panels of grouped bars).
"""

import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
STEPS = 50_000
BLOCKS = (1, 8, 32)
TARGET_PERIOD_FRAMES = 20
SEED = 6


def load_native(path):
    sys.path.insert(0, path)
    import _native  # noqa: E402
    return _native


def epsilon(native, cost, counts, params):
    """ε = (2a + b)/3, a and b over the block candidates that do not join two states' groups at
    most max(1, min node gap) steps apart (flowgraph_settings.same_moment and threshold)."""
    t = native.select_transitions(cost, counts, params)
    offsets = np.concatenate([[0], np.cumsum(counts)])
    state = np.repeat(np.arange(len(counts)), counts)
    rows, cols = np.asarray(t["row"], np.int64), np.asarray(t["col"], np.int64)
    sr, sc = state[rows], state[cols]
    moment = (sr != sc) & (np.abs((rows - offsets[sr]) - (cols - offsets[sc]))
                           <= max(1, params.min_node_gap))
    costs = np.asarray(t["cost"])
    own = costs[~moment] if np.any(~moment) else costs
    return (2.0 * own.min() + own.max()) / 3.0


def read_graph_file(path):
    with np.load(path, allow_pickle=False) as data:
        cost = np.array(data["cost"])
        counts = [int(v) for v in data["state_node_counts"]]
        folders = [str(v) for v in data["state_folders"]]
        _, gap, _, alpha, beta = (float(v) for v in data["settings"])
    return cost, counts, folders, int(gap), alpha, beta


def walk_figures(native, graph, cost, strategy, hold, steps_per_frame):
    """(temporal share, mean frames between transitions, mean cost of transitions taken, share
    of transitions forced inside a hold: the time line ended with no long transition)."""
    bias = native.WalkBias.UNIFORM if strategy == "random" else native.WalkBias.TEMPORAL
    walk = native.RandomWalk(graph, SEED, bias, 0.875, 0, transition_hold=hold)
    if strategy == "target":
        period = TARGET_PERIOD_FRAMES * steps_per_frame
        targets = (np.arange(STEPS) // period) % graph.state_count
    else:
        targets = np.full(STEPS, -1)
    nodes = np.concatenate([[walk.current], walk.run(targets)])
    states, steps = np.asarray(graph.node_states)[nodes], np.asarray(graph.node_steps)[nodes]
    temporal = (states[1:] == states[:-1]) & (steps[1:] == steps[:-1] + 1)
    jumps = np.flatnonzero(~temporal)
    # A transition edge i -> j + 1 stands for the candidate (i, j): its cost is c(i, j).
    costs = cost[nodes[jumps], nodes[jumps + 1] - 1] if jumps.size else np.zeros(0)
    gap = (np.diff(jumps).mean() / steps_per_frame) if jumps.size > 1 else float("nan")
    forced = walk.forced_transitions / max(jumps.size, 1)
    return (float(temporal.mean()), float(gap),
            float(costs.mean()) if costs.size else float("nan"), float(forced))


def main():
    args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    if len(args) < 2:
        sys.exit(__doc__)
    out_dir, graph_path = args[0], args[1]
    native = load_native(args[2] if len(args) > 2 else
                         os.path.join(os.path.dirname(os.path.dirname(HERE)), "build", "native"))
    cost, counts, folders, gap, alpha, beta = read_graph_file(graph_path)
    first = native.PathlineFile.open(os.path.join(folders[0], "pathlines.bin"))
    lifetime, steps_per_frame = int(first.layout.samples), int(first.nodes_per_frame)
    strategies = ("random", "biased", "target")
    rows = {}
    for block in BLOCKS:
        p = native.FlowGraphParams()
        p.block_size, p.min_node_gap, p.alpha, p.beta = block, gap, alpha, beta
        try:
            p.epsilon_mode, p.epsilon = native.EpsilonMode.EXPLICIT, float(
                epsilon(native, cost, counts, p))
            graph = native.FlowGraph.build(cost, counts, p)
        except ValueError as e:
            print(f"B = {block}: {e}")
            continue
        kept = int(np.sum(graph.transitions()["kept"]))
        for strategy in strategies:
            for hold in (0, lifetime):
                rows[(block, strategy, hold)] = walk_figures(native, graph, cost, strategy, hold,
                                                             steps_per_frame)
        print(f"B = {block}: {kept} transitions kept")
    print(f"{len(cost)} nodes, L = {lifetime} node steps, {steps_per_frame} node steps per frame")
    print("B   strategy  hold  temporal share  frames between transitions  mean transition cost"
          "  forced")
    for (block, strategy, hold), (share, frames, c, forced) in rows.items():
        print(f"{block:<3} {strategy:<9} {hold:>4}  {share:14.3f}  {frames:26.2f}  {c:20.4g}"
              f"  {forced:6.3f}")
    plot(rows, lifetime, os.path.join(out_dir, "figure6.png"))


def plot(rows, lifetime, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    blocks = sorted({k[0] for k in rows})
    strategies = ("random", "biased", "target")
    labels = {"random": "random (1/d)", "biased": "temporal bias γ = 0.875", "target": "target states"}
    fig, axes = plt.subplots(1, 3, figsize=(12, 4.2))
    titles = ("share of temporal edges", "frames between transitions", "mean cost of transitions")
    width = 0.8 / (2 * len(strategies))
    colors = {"random": "#d0703c", "biased": "#3c78d0", "target": "#5aa05a"}
    for a, ax in enumerate(axes):
        for s_i, strategy in enumerate(strategies):
            for h_i, hold in enumerate((0, lifetime)):
                x = np.arange(len(blocks)) + (2 * s_i + h_i - len(strategies) + 0.5) * width
                y = [rows.get((b, strategy, hold), (np.nan,) * 4)[a] for b in blocks]
                ax.bar(x, y, width, color=colors[strategy], alpha=1.0 if hold else 0.45,
                       label=f"{labels[strategy]}, {'hold L' if hold else 'no hold'}")
        ax.set_xticks(np.arange(len(blocks)))
        ax.set_xticklabels([f"B = {b}" for b in blocks])
        ax.set_title(titles[a], fontsize=10)
        if a == 1:
            ax.set_yscale("log")
    handles, names = axes[0].get_legend_handles_labels()
    fig.legend(handles, names, fontsize=8, loc="lower center", ncol=3, frameon=False)
    fig.suptitle("Figure 6: traversal strategies on the campfire's flow graph (50,000 node steps "
                 "each)", fontsize=11)
    fig.tight_layout(rect=(0, 0.12, 1, 1))
    fig.savefig(path, dpi=90)
    print(f"-> {path}")


if __name__ == "__main__":
    main()
