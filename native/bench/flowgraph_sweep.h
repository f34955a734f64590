#pragma once
/// \file flowgraph_sweep.h
/// Figure 7 of [Graph Fire Synthesis] ("comparison of the time cost between simulation and
/// synthesis on different problem scales") as data: `plume_bench_flowgraph_graph --sweep`.

namespace plume::bench {

/// Runs the sweep and prints one JSON object per line (see flowgraph_sweep.cpp); returns the
/// exit code. Options (--name=value): nodes (comma list, default 100,200,500,1000), pathlines
/// (default 800,1600,3200), samples (L, default 48), threads (default 0: all cores), frames
/// (synthesized and simulated frames timed per size, default 6), sim_warmup (simulated frames
/// before timing, default 12; 0 skips the simulation), dir (temporary files, default $TMPDIR or
/// /tmp).
int runFlowgraphSweep(int argc, char** argv);

}  // namespace plume::bench
