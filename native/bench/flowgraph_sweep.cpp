/// \file flowgraph_sweep.cpp
/// Figure 7's data ([Graph Fire Synthesis] §5.2): for every pathlines-per-node count |Ω|,
/// - "build": the graph build the add-on runs (α, β streamed, C streamed, FlowGraph::build) for
///   every node count N, on synthetic groups (tests/flowgraph_groups.h) written to pathline
///   files of 100 nodes per state; wall seconds of each part, the peak resident set, reads;
/// - "synthesis": one frame of synthesis, i.e. nodes_per_frame = 2 node steps (step_node from a
///   file, prepared groups cached as in the add-on) + gathering the live particles +
///   rasterizing them into VDB grids at the cell size 1/n of the matching simulation below, on
///   fire-like groups (bench_fire_groups.h: a 1 m burner, flames up to 2.5 m, so more voxels
///   than the simulated 1 m box: the comparison favours simulation) with a full ring of L live
///   groups; it does not depend on N;
/// - "simulation": one simulated frame of the fire that would record |Ω| seeds per node step: a
///   burner of s × s × 2 cells (8 seeds a cell, s = round(√(|Ω|/16))) in an n³ grid with
///   n = round(s / 0.22) (the burner covers the same share of the floor), after sim_warmup
///   frames. |Ω| = 800, 1600, 3200 give 32³, 45³, 64³.
/// One JSON object per line: {"kind": "build" | "synthesis" | "simulation", ...}.

#include "bench/flowgraph_sweep.h"

#include "bench/bench_fire_groups.h"
#include "bench/bench_memory.h"
#include "fields/fire_raster.h"
#include "flowgraph/cost_matrix_stream.h"
#include "flowgraph/flow_graph.h"
#include "flowgraph/magnitude_weights.h"
#include "flowgraph/synthesizer.h"
#include "tests/flowgraph_fire.h"
#include "tests/flowgraph_group_files.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace plume::bench {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

constexpr int kStateNodes = 100;     ///< nodes per state file
constexpr int kNodesPerFrame = 2;    ///< L = 48 samples span one second at 24 frames per second
constexpr float kNodeDt = 1.f / 48.f;

struct Options {
  std::vector<int> nodes{100, 200, 500, 1000};
  std::vector<int> pathlines{800, 1600, 3200};
  int samples = 48, threads = 0, frames = 6, simWarmup = 12;
  std::string dir;
};

std::vector<int> intList(const std::string& s) {
  std::vector<int> v;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) v.push_back(std::stoi(item));
  return v;
}

Options parse(int argc, char** argv) {
  Options o;
  const char* tmp = std::getenv("TMPDIR");
  o.dir = tmp && *tmp ? tmp : "/tmp";
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    const std::size_t eq = arg.find('=');
    if (arg == "--sweep" || eq == std::string::npos) continue;
    const std::string key = arg.substr(2, eq - 2), value = arg.substr(eq + 1);
    if (key == "nodes") o.nodes = intList(value);
    else if (key == "pathlines") o.pathlines = intList(value);
    else if (key == "samples") o.samples = std::stoi(value);
    else if (key == "threads") o.threads = std::stoi(value);
    else if (key == "frames") o.frames = std::stoi(value);
    else if (key == "sim_warmup") o.simWarmup = std::stoi(value);
    else if (key == "dir") o.dir = value;
    else throw std::invalid_argument("unknown option --" + key);
  }
  return o;
}

/// The graph build of the add-on for the first `states` files.
void build(const Options& o, const std::vector<PathlineFile>& files, int states, int pathlines) {
  std::vector<const PathlineFile*> used;
  for (int s = 0; s < states; ++s) used.push_back(&files[std::size_t(s)]);
  const NodeFiles nodes(used);
  resetPeakRss();
  const double rssBefore = statusMb("VmRSS:");
  const Clock::time_point t0 = Clock::now();
  FlowGraphParams p;
  p.threads = o.threads;
  const FlowWeights w = sameMagnitudeWeights(nodes, o.threads);
  p.alpha = w.alpha;
  p.beta = w.beta;
  const double weights = since(t0);
  CostStreamStats stats;
  const CostMatrix c = computeCostMatrix(nodes, p, nullptr, CostStreamParams(), &stats);
  const Clock::time_point t1 = Clock::now();
  std::string error;
  long long transitions = 0;
  try {
    const FlowGraph g = FlowGraph::build(c, nodes.counts(), p);
    transitions = g.edgeCount() - g.temporalEdgeCount();
  } catch (const std::exception& e) {  // a graph with too few transitions still timed its matrix
    error = e.what();
  }
  const double graph = since(t1), total = since(t0);
  std::printf(
      "{\"kind\": \"build\", \"nodes\": %d, \"pathlines\": %d, \"samples\": %d, \"build_s\": %.4f, "
      "\"weights_s\": %.4f, \"cost_s\": %.4f, \"graph_s\": %.4f, \"read_s\": %.4f, \"group_reads\": %lld, "
      "\"row_nodes\": %d, \"peak_rss_MB\": %.1f, \"rss_before_MB\": %.1f, \"transitions\": %lld, "
      "\"error\": \"%s\"}\n",
      nodes.size(), pathlines, o.samples, total, weights, stats.seconds, graph, stats.readSeconds, stats.groupReads,
      stats.rowNodes, statusMb("VmHWM:"), rssBefore, transitions, error.empty() ? "" : "graph build failed");
  std::fflush(stdout);
}

/// The burner side s and grid n of the fire that records about `pathlines` seeds a node step.
std::pair<int, int> matchingFire(int pathlines) {
  const int side = std::max(1, int(std::lround(std::sqrt(pathlines / 16.0))));
  return {side, int(std::lround(side / 0.22))};
}

/// One synthesized frame: kNodesPerFrame node steps, gather, rasterize (mean of o.frames).
void synthesis(const Options& o, int pathlines) {
  const std::vector<PathlineGroup> groups = fireGroups(8, pathlines, o.samples, kNodeDt);
  const std::string path = o.dir + "/plume_sweep_fire_" + std::to_string(::getpid()) + "_" +
                           std::to_string(pathlines) + ".bin";
  {
    PathlineFileInfo info;
    info.layout = groups[0].layout;
    info.resolution = glm::ivec3(128, 64, 64);
    info.cellSize = 1.f / 64.f;
    info.nodesPerFrame = kNodesPerFrame;
    PathlineFileWriter w(path, info);
    for (const PathlineGroup& g : groups) w.append(g);
    w.finish();
  }
  const PathlineFile file = PathlineFile::open(path);
  Synthesizer s(file.layout(), o.threads, std::size_t(1) << 30);
  int n = 0;
  for (; n < 2 * o.samples; ++n) s.stepNode(file, n % 8, 0, glm::vec3(0.2f, 0.f, 0.f));  // a full ring
  FireRasterParams raster;
  raster.voxelSize = 1.f / float(matchingFire(pathlines).second);
  raster.threads = o.threads;
  SynthParticles out;
  double step = 0.0, gather = 0.0, rasterize = 0.0;
  for (int f = 0; f < o.frames; ++f) {
    Clock::time_point t = Clock::now();
    for (int k = 0; k < kNodesPerFrame; ++k) s.stepNode(file, n++ % 8, 0, glm::vec3(0.2f, 0.f, 0.f));
    step += since(t);
    t = Clock::now();
    s.gather(out);
    gather += since(t);
    t = Clock::now();
    const FireGrids g = rasterizeFire({out.positions.data(), out.density.data(), out.temperature.data(), out.size()},
                                      raster);
    rasterize += since(t);
  }
  std::remove(path.c_str());
  const double f = double(o.frames);
  std::printf(
      "{\"kind\": \"synthesis\", \"pathlines\": %d, \"samples\": %d, \"nodes_per_frame\": %d, "
      "\"particles\": %zu, \"voxel_size\": %.5g, \"step_s\": %.4g, \"gather_s\": %.4g, \"raster_s\": %.4g, "
      "\"frame_s\": %.4g}\n",
      pathlines, o.samples, kNodesPerFrame, out.size(), double(raster.voxelSize), step / f, gather / f, rasterize / f,
      (step + gather + rasterize) / f);
  std::fflush(stdout);
}

/// One simulated frame of the fire recording about `pathlines` seeds per node step.
void simulation(const Options& o, int pathlines) {
  const auto [side, n] = matchingFire(pathlines);
  SmokeSolver solver(testing::fireParams(n, o.threads));
  solver.addSource(testing::fireBurner(n, side), testing::fireFuel());
  for (int f = 0; f < o.simWarmup; ++f) solver.advanceFrame();
  const Clock::time_point t = Clock::now();
  for (int f = 0; f < o.frames; ++f) solver.advanceFrame();
  std::printf(
      "{\"kind\": \"simulation\", \"pathlines\": %d, \"seeds\": %d, \"resolution\": %d, \"frame_s\": %.5f}\n",
      pathlines, 16 * side * side, n, since(t) / double(o.frames));
  std::fflush(stdout);
}

}  // namespace

int runFlowgraphSweep(int argc, char** argv) {
  try {
    const Options o = parse(argc, argv);
    int maxNodes = 0;
    for (int n : o.nodes) {
      if (n < kStateNodes || n % kStateNodes) throw std::invalid_argument("--nodes must be multiples of 100");
      maxNodes = std::max(maxNodes, n);
    }
    for (int pathlines : o.pathlines) {
      const std::vector<std::string> paths = testing::writeOscillatingFiles(
          o.dir + "/plume_sweep_" + std::to_string(::getpid()) + "_" + std::to_string(pathlines) + "_",
          std::vector<int>(std::size_t(maxNodes / kStateNodes), kStateNodes), pathlines, o.samples, 1);
      {
        const std::vector<PathlineFile> files = testing::openFiles(paths);
        for (int n : o.nodes) build(o, files, n / kStateNodes, pathlines);
      }
      for (const std::string& p : paths) std::remove(p.c_str());
      synthesis(o, pathlines);
      if (o.simWarmup > 0) simulation(o, pathlines);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "plume_bench_flowgraph_graph --sweep: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace plume::bench
