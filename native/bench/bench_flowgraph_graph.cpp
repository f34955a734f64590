/// \file bench_flowgraph_graph.cpp
/// Benchmark of the flow-graph build ([Graph Fire Synthesis] §4.3): the cost matrix of eq. 9-10
/// and the graph (block candidates, ε, pruning) for 1,000 nodes of synthetic groups at
/// |Ω| = 3200 pathlines and L = 48 samples (the paper's campfire: 3217 pathlines per node), with
/// every group in memory (BM_CostMatrix, what the add-on did before) and streamed from pathline
/// files (BM_CostMatrixStreamed, what it does now), at 1 and 2 threads. Not a test: run
/// build/native/plume_bench_flowgraph_graph by hand; with --sweep it prints Figure 7's data
/// instead (flowgraph_sweep.h).
///
/// Counters: pair_values_per_s = N(N−1)/2 · 5|Ω|L / time (sample differences per second);
/// process_cpu_s = CPU seconds of all threads (on a shared machine wall time also counts waits);
/// peak_rss_MB = the process's peak resident set during the build (reset through
/// /proc/self/clear_refs before it, so each benchmark sees its own): for BM_CostMatrix it
/// includes the 3 GB of groups, allocated before and resident throughout, as they were in the
/// add-on; peak_rss_delta_MB = that peak minus the resident set before the build. The streamed
/// build holds no group before it starts (the in-memory groups are freed first) and reports
/// group_reads, read_share (the wall-time share spent reading groups) and weights_s (α, β of
/// eq. 9 streamed the same way, two passes). BM_GraphBuild times FlowGraph::build on a ready C.
/// For a clean peak run each in its own process (--benchmark_filter=BM_CostMatrixStreamed/1000/2):
/// memory freed by an earlier benchmark may stay with the allocator and count as resident.

#include "bench/bench_memory.h"
#include "bench/flowgraph_sweep.h"
#include "flowgraph/cost_matrix.h"
#include "flowgraph/cost_matrix_stream.h"
#include "flowgraph/flow_graph.h"
#include "flowgraph/magnitude_weights.h"
#include "tests/flowgraph_group_files.h"
#include "tests/flowgraph_groups.h"

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

namespace plume {
namespace {

using bench::processCpuSeconds;
using bench::resetPeakRss;
using bench::statusMb;

constexpr int kParticles = 3200;
constexpr int kSamples = 48;

std::vector<int> counts(int n) {
  const int a = n * 2 / 5, b = n * 7 / 20;
  return {a, b, n - a - b};
}

/// N nodes in three states (40%, 35%, 25%), generated once per N; release() frees them.
std::vector<PathlineGroup>& groupCache() {
  static std::vector<PathlineGroup> g;
  return g;
}
int cachedNodes = -1;
const std::vector<PathlineGroup>& groups(int n) {
  std::vector<PathlineGroup>& g = groupCache();
  if (cachedNodes != n) {
    g.clear();
    g.shrink_to_fit();
    g = testing::oscillatingGroups(counts(n), kParticles, kSamples, 1);
    cachedNodes = n;
  }
  return g;
}
void releaseGroups() {
  groupCache().clear();
  groupCache().shrink_to_fit();
  cachedNodes = -1;
}

/// The same N groups written to three pathline files in $TMPDIR (or /tmp) one group at a time,
/// removed at exit.
class GraphFiles {
 public:
  explicit GraphFiles(int n) {
    const char* dir = std::getenv("TMPDIR");
    mPaths = testing::writeOscillatingFiles(std::string(dir && *dir ? dir : "/tmp") + "/plume_bench_graph_" +
                                                std::to_string(::getpid()) + "_" +
                                                std::to_string(n) + "_",
                                            counts(n), kParticles, kSamples, 1);
    mFiles = testing::openFiles(mPaths);
    mNodes = std::make_unique<NodeFiles>(testing::filePointers(mFiles));
  }
  ~GraphFiles() {
    for (const std::string& p : mPaths) std::remove(p.c_str());
  }
  const NodeFiles& nodes() const { return *mNodes; }

 private:
  std::vector<std::string> mPaths;
  std::vector<PathlineFile> mFiles;
  std::unique_ptr<NodeFiles> mNodes;
};

const GraphFiles& graphFiles(int n) {
  static std::unique_ptr<GraphFiles> f;
  static int cached = -1;
  if (cached != n) {
    f.reset();
    f = std::make_unique<GraphFiles>(n);
    cached = n;
  }
  return *f;
}

void rateCounters(benchmark::State& state, int n) {
  const double values = 0.5 * n * (n - 1.0) * 5.0 * kParticles * kSamples;
  state.counters["pair_values_per_s"] = benchmark::Counter(values * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["groups_GB"] = double(n) * 5.0 * kParticles * kSamples * 4.0 / 1e9;
}

/// Args: nodes, threads. Every group in memory.
void BM_CostMatrix(benchmark::State& state) {
  const int n = int(state.range(0));
  const auto ptrs = testing::pointers(groups(n));
  FlowGraphParams p;
  p.threads = int(state.range(1));
  const double before = statusMb("VmRSS:");
  resetPeakRss();
  const double cpu = processCpuSeconds();
  for (auto _ : state) benchmark::DoNotOptimize(computeCostMatrix(ptrs, p));
  state.counters["peak_rss_MB"] = statusMb("VmHWM:");
  state.counters["peak_rss_delta_MB"] = statusMb("VmHWM:") - before;
  // All threads' CPU time: the work itself, whatever else runs on the machine.
  state.counters["process_cpu_s"] = (processCpuSeconds() - cpu) / double(state.iterations());
  rateCounters(state, n);
}

/// Args: nodes, threads. Streamed from the pathline files with the default blocks.
void BM_CostMatrixStreamed(benchmark::State& state) {
  releaseGroups();  // the in-memory benchmarks' groups: this build must not count them
  const int n = int(state.range(0));
  const NodeFiles& nodes = graphFiles(n).nodes();
  FlowGraphParams p;
  p.threads = int(state.range(1));
  const double before = statusMb("VmRSS:");
  resetPeakRss();
  const double cpu = processCpuSeconds();
  CostStreamStats stats;
  double weights = 0.0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(sameMagnitudeWeights(nodes, p.threads));
    weights += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    benchmark::DoNotOptimize(computeCostMatrix(nodes, p, nullptr, CostStreamParams(), &stats));
  }
  state.counters["peak_rss_MB"] = statusMb("VmHWM:");
  state.counters["peak_rss_delta_MB"] = statusMb("VmHWM:") - before;
  state.counters["process_cpu_s"] = (processCpuSeconds() - cpu) / double(state.iterations());
  state.counters["weights_s"] = weights / double(state.iterations());
  state.counters["cost_s"] = stats.seconds;
  state.counters["read_share"] = stats.readSeconds / stats.seconds;
  state.counters["group_reads"] = double(stats.groupReads);
  state.counters["row_nodes"] = stats.rowNodes;
  rateCounters(state, n);
}

/// Args: nodes. Candidates, ε, edges and pruning on the cost matrix of the synthetic groups.
void BM_GraphBuild(benchmark::State& state) {
  const int n = int(state.range(0));
  FlowGraphParams p;
  const CostMatrix c = computeCostMatrix(testing::pointers(groups(n)), p);
  releaseGroups();
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
BENCHMARK(BM_CostMatrixStreamed)
    ->Args({1000, 1})
    ->Args({1000, 2})
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

}  // namespace
}  // namespace plume

int main(int argc, char** argv) {
  for (int a = 1; a < argc; ++a)
    if (std::strcmp(argv[a], "--sweep") == 0) return plume::bench::runFlowgraphSweep(argc, argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
