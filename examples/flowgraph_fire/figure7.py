"""Figure 7 of the paper ("comparison of the time cost between simulation and synthesis on
different problem scales"): the flow-graph build time against the node count N, one line per
pathline count |Ω| per node, and the time of one frame against |Ω|: synthesized (node steps,
gathering and rasterizing the particles) beside simulated (the fire that records |Ω| seeds per
node step, grids 32³, 45³, 64³).

    /usr/bin/python3 examples/flowgraph_fire/figure7.py OUT_DIR [--bench PATH] [--nodes 100,200,500,1000]
        [--pathlines 800,1600,3200] [--frames 6] [--sim-warmup 12] [--threads 0] [--from-jsonl FILE]

Runs `PATH --sweep` (default build/native/plume_bench_flowgraph_graph, built with the project;
see native/bench/flowgraph_sweep.cpp for what is timed), keeps its JSON lines in
OUT_DIR/figure7.jsonl and plots OUT_DIR/figure7.png (--from-jsonl: plot a kept run instead). A few minutes on 2 cores; the sweep writes
pathline files of up to N × |Ω| × 48 × 20 bytes (3.1 GB at 1,000 × 3,200) to $TMPDIR or /tmp.
"""

import argparse
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_BENCH = os.path.join(ROOT, "build", "native", "plume_bench_flowgraph_graph")


def run_sweep(args, out_dir):
    """The bench's JSON lines (also written to OUT_DIR/figure7.jsonl), as dicts."""
    if not os.access(args.bench, os.X_OK):
        sys.exit(f"figure7: no benchmark program at {args.bench} (build the project, or pass --bench)")
    cmd = [args.bench, "--sweep", f"--nodes={args.nodes}", f"--pathlines={args.pathlines}",
           f"--frames={args.frames}", f"--sim_warmup={args.sim_warmup}", f"--threads={args.threads}"]
    print("figure7:", " ".join(cmd), flush=True)
    rows = []
    with open(os.path.join(out_dir, "figure7.jsonl"), "w") as log, \
            subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True) as p:
        for line in p.stdout:
            log.write(line)
            rows.append(json.loads(line))
            print("  ", line.rstrip(), flush=True)
    if p.returncode != 0:
        sys.exit(f"figure7: {args.bench} --sweep failed (exit {p.returncode})")
    return rows


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    builds = [r for r in rows if r["kind"] == "build"]
    synth = sorted((r for r in rows if r["kind"] == "synthesis"), key=lambda r: r["pathlines"])
    sim = sorted((r for r in rows if r["kind"] == "simulation"), key=lambda r: r["pathlines"])
    fig, (a, b) = plt.subplots(1, 2, figsize=(8.4, 3.4), dpi=100)
    for omega in sorted({r["pathlines"] for r in builds}):
        pts = sorted((r["nodes"], r["build_s"]) for r in builds if r["pathlines"] == omega)
        a.plot(*zip(*pts), marker="o", label=f"|Ω| = {omega}")
    a.set_xlabel("nodes N")
    a.set_ylabel("graph build (s)")
    a.set_title("Build Flow Graph (C streamed, 2 cores)", fontsize=10)
    a.grid(alpha=0.3)
    a.legend(fontsize=8)
    if synth:
        x = [r["pathlines"] for r in synth]
        b.plot(x, [1e3 * r["frame_s"] for r in synth], marker="o", color="tab:red",
               label="synthesis: whole frame")
        b.plot(x, [1e3 * r["raster_s"] for r in synth], marker=".", ls="--", color="tab:red",
               alpha=0.6, label="  of which rasterizing")
        b.plot(x, [1e3 * (r["step_s"] + r["gather_s"]) for r in synth], marker=".", ls=":",
               color="tab:red", alpha=0.6, label="  of which walk, eq. 13, gather")
    if sim:
        b.plot([r["pathlines"] for r in sim], [1e3 * r["frame_s"] for r in sim], marker="s",
               color="k", label="simulation (" + ", ".join(f"{r['resolution']}³" for r in sim) + ")")
    b.set_yscale("log")
    b.set_xlabel("pathlines per node |Ω|")
    b.set_ylabel("time per frame (ms)")
    b.set_title("One frame: synthesis against simulation", fontsize=10)
    b.grid(alpha=0.3, which="both")
    b.set_ylim(1, 3e4)  # room above the lines for the legend
    b.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out_dir")
    ap.add_argument("--bench", default=DEFAULT_BENCH)
    ap.add_argument("--nodes", default="100,200,500,1000")
    ap.add_argument("--pathlines", default="800,1600,3200")
    ap.add_argument("--frames", type=int, default=6)
    ap.add_argument("--sim-warmup", type=int, default=12)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--from-jsonl", help="plot the JSON lines of an earlier run, run nothing")
    args = ap.parse_args(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else None)
    os.makedirs(args.out_dir, exist_ok=True)
    if args.from_jsonl:
        with open(args.from_jsonl) as f:
            rows = [json.loads(line) for line in f if line.strip()]
    else:
        rows = run_sweep(args, args.out_dir)
    path = os.path.join(args.out_dir, "figure7.png")
    plot(rows, path)
    print(f"figure7: wrote {path}")


if __name__ == "__main__":
    main()
