/// \file bench_flowgraph_graph.cpp
/// Benchmark of the flow-graph build (graph_fire_synthesis.txt §4.3): the cost matrix
/// of eq. 9-10 and the graph (block candidates, ε, pruning) for 1,000 nodes of synthetic
/// groups at |Ω| = 3200 pathlines and L = 48 samples (the paper's campfire: 3217 pathlines per
/// node), at 1 and 2 threads. Not a test: run build/native/plume_bench_flowgraph_graph by hand.
///
/// Counters: pair_values_per_s = N(N−1)/2 · 5|Ω|L / time (sample differences per second);
/// process_cpu_s = CPU seconds of all threads (on a shared machine wall time also counts waits);
/// peak_rss_delta_MB = the process's peak resident set during the build minus the resident set
/// before it (the peak is reset through /proc/self/clear_refs, so each benchmark sees its own;
/// the 3 GB of groups are allocated before and not counted). BM_GraphBuild times
/// FlowGraph::build on a ready cost matrix.

#include "flowgraph/cost_matrix.h"
#include "flowgraph/flow_graph.h"
#include "tests/flowgraph_groups.h"

#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

namespace plume {
namespace {

constexpr int kParticles = 3200;
constexpr int kSamples = 48;

/// CPU seconds of every thread of the process so far (user + system).
double processCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

/// VmRSS or VmHWM of /proc/self/status in MB.
double statusMb(const char* key) {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind(key, 0) == 0) return std::stod(line.substr(std::strlen(key))) / 1024.0;
  return 0.0;
}

/// Resets the peak resident set (VmHWM) to the current one (Linux >= 4.0).
void resetPeakRss() {
  if (std::FILE* f = std::fopen("/proc/self/clear_refs", "w")) {
    std::fputs("5", f);
    std::fclose(f);
  }
}

/// N nodes in three states (40%, 35%, 25%), generated once per N.
const std::vector<PathlineGroup>& groups(int n) {
  static int cached = -1;
  static std::vector<PathlineGroup> g;
  if (cached != n) {
    g.clear();
    g.shrink_to_fit();
    const int a = n * 2 / 5, b = n * 7 / 20;
    g = testing::oscillatingGroups({a, b, n - a - b}, kParticles, kSamples, 1);
    cached = n;
  }
  return g;
}

std::vector<int> counts(int n) {
  const int a = n * 2 / 5, b = n * 7 / 20;
  return {a, b, n - a - b};
}

/// Args: nodes, threads.
void BM_CostMatrix(benchmark::State& state) {
  const int n = int(state.range(0));
  const auto ptrs = testing::pointers(groups(n));
  FlowGraphParams p;
  p.threads = int(state.range(1));
  const double before = statusMb("VmRSS:");
  resetPeakRss();
  const double cpu = processCpuSeconds();
  for (auto _ : state) benchmark::DoNotOptimize(computeCostMatrix(ptrs, p));
  state.counters["peak_rss_delta_MB"] = statusMb("VmHWM:") - before;
  // All threads' CPU time: the work itself, whatever else runs on the machine.
  state.counters["process_cpu_s"] = (processCpuSeconds() - cpu) / double(state.iterations());
  const double values = 0.5 * n * (n - 1.0) * 5.0 * kParticles * kSamples;
  state.counters["pair_values_per_s"] = benchmark::Counter(values * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["groups_GB"] = double(n) * 5.0 * kParticles * kSamples * 4.0 / 1e9;
}

/// Args: nodes. Candidates, ε, edges and pruning on the cost matrix of the synthetic groups.
void BM_GraphBuild(benchmark::State& state) {
  const int n = int(state.range(0));
  FlowGraphParams p;
  const CostMatrix c = computeCostMatrix(testing::pointers(groups(n)), p);
  const double before = statusMb("VmRSS:");
  resetPeakRss();
  FlowGraph g;
  for (auto _ : state) g = FlowGraph::build(c, counts(n), p);
  state.counters["peak_rss_delta_MB"] = statusMb("VmHWM:") - before;
  state.counters["edges"] = g.edgeCount();
  state.counters["transitions"] = g.edgeCount() - g.temporalEdgeCount();
  int pruned = 0;
  for (int s : g.prunedPerState()) pruned += s;
  state.counters["pruned"] = pruned;
}

BENCHMARK(BM_CostMatrix)->Args({1000, 1})->Args({1000, 2})->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();
BENCHMARK(BM_GraphBuild)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace plume

BENCHMARK_MAIN();
