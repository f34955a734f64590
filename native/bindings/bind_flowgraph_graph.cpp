/// \file bind_flowgraph_graph.cpp
/// The flow graph for Python ([Graph Fire Synthesis] §4.3-5.1): FlowGraphParams, the cost
/// matrix of eq. 9-10 from PathlineGroup objects (bind_pathline_group.cpp), the graph with its
/// pruning, random walks and the Figure 4 picture. Conversions and docstrings only; long calls
/// release the GIL. std::invalid_argument becomes ValueError.

#include "bindings/bindings.h"
#include "bindings/convert.h"

#include "flowgraph/cost_matrix.h"
#include "flowgraph/cost_matrix_image.h"
#include "flowgraph/cost_matrix_stream.h"
#include "flowgraph/flow_graph.h"
#include "flowgraph/magnitude_weights.h"
#include "flowgraph/random_walk.h"

#include <pybind11/stl.h>

#include <algorithm>
#include <cstring>
#include <memory>

namespace py = pybind11;

namespace plume::bindings {
namespace {

/// A Python sequence of PathlineGroup as pointers (the sequence must outlive their use).
std::vector<const PathlineGroup*> groupPointers(const py::sequence& groups) {
  std::vector<const PathlineGroup*> p;
  p.reserve(py::len(groups));
  for (std::size_t n = 0; n < py::len(groups); ++n) {
    if (!py::isinstance<PathlineGroup>(groups[n]))
      throw py::value_error("groups[" + std::to_string(n) + "] is not a PathlineGroup");
    p.push_back(&groups[n].cast<const PathlineGroup&>());
  }
  return p;
}

/// A Python sequence of PathlineFile, one per state in order, as NodeFiles (the sequence must
/// outlive its use). ValueError on other items or what NodeFiles() rejects.
NodeFiles nodeFiles(const py::sequence& files) {
  std::vector<const PathlineFile*> p;
  for (std::size_t n = 0; n < py::len(files); ++n) {
    if (!py::isinstance<PathlineFile>(files[n]))
      throw py::value_error("files[" + std::to_string(n) + "] is not a PathlineFile");
    p.push_back(&files[n].cast<const PathlineFile&>());
  }
  return NodeFiles(std::move(p));
}

/// CostStreamParams from row_block_mb and column_nodes (ValueError out of range).
CostStreamParams streamParams(double rowBlockMb, int columnNodes) {
  if (!(rowBlockMb >= 1.0 && rowBlockMb <= 1048576.0))
    throw py::value_error("row_block_mb must be in [1, 1048576] MB (got " + std::to_string(rowBlockMb) + ")");
  CostStreamParams s;
  s.rowBlockBytes = std::size_t(rowBlockMb * 1048576.0);
  s.columnNodes = columnNodes;
  return s;
}

/// CostStreamStats as a dict.
py::dict statsDict(const CostStreamStats& s) {
  py::dict d;
  d["row_nodes"] = s.rowNodes;
  d["column_nodes"] = s.columnNodes;
  d["group_reads"] = s.groupReads;
  d["read_seconds"] = s.readSeconds;
  d["seconds"] = s.seconds;
  return d;
}

/// An (N, N) float64 array as a checked CostMatrix (ValueError otherwise).
CostMatrix toCost(const py::object& o) {
  const DoubleArrayC a = DoubleArrayC::ensure(o);
  if (!a || a.ndim() != 2 || a.shape(0) != a.shape(1))
    throw py::value_error("cost must be a square (N, N) float array");
  std::vector<double> v(std::size_t(a.size()));
  if (!v.empty()) std::memcpy(v.data(), a.data(), v.size() * sizeof(double));
  py::gil_scoped_release release;
  return CostMatrix::fromValues(int(a.shape(0)), std::move(v));
}

/// An (N, N) float64 NumPy copy of C.
py::array_t<double> costArray(const CostMatrix& c) {
  py::array_t<double> a({py::ssize_t(c.size()), py::ssize_t(c.size())});
  if (c.size()) std::memcpy(a.mutable_data(), c.values().data(), c.values().size() * sizeof(double));
  return a;
}

/// computeCostMatrix() run by a worker thread while another polls progress or cancels: from
/// PathlineGroups in memory, or streamed from the states' PathlineFiles (`files` set).
struct CostMatrixJob {
  py::object groups;  // keeps the PathlineGroups or PathlineFiles alive
  std::vector<const PathlineGroup*> pointers;
  std::unique_ptr<NodeFiles> files;
  CostStreamParams stream;
  CostStreamStats stats;
  FlowGraphParams params;
  CostMatrixProgress progress;
  CostMatrix cost;
  bool finished = false;
};

void bindParams(py::module_& m) {
  py::enum_<EpsilonMode>(m, "EpsilonMode", "How ε of eq. 11 is chosen from a, b (§4.3).")
      .value("TWO_THIRDS", EpsilonMode::TwoThirds, "ε = (2a + b) / 3, the paper's.")
      .value("EXPLICIT", EpsilonMode::Explicit, "FlowGraphParams.epsilon, which must lie in [a, b].");
  py::enum_<WalkBias>(m, "WalkBias", "Edge choice of a random walk without target (§5.1).")
      .value("UNIFORM", WalkBias::Uniform, "p = 1 / d(V_i).")
      .value("TEMPORAL", WalkBias::Temporal, "Eq. 12: γ on the temporal edge, (1 − γ)/(d − 1) on the others.");

  py::class_<FlowGraphParams> c(m, "FlowGraphParams", "Settings of the flow graph (§4.3).");
  c.def(py::init<>());
  c.def_readwrite("alpha", &FlowGraphParams::alpha, "α of eq. 9: weight of the density difference (>= 0).");
  c.def_readwrite("beta", &FlowGraphParams::beta, "β of eq. 9: weight of the temperature difference (>= 0).");
  c.def_readwrite("block_size", &FlowGraphParams::blockSize, "B: one candidate per B×B block (default 32, >= 1).");
  c.def_readwrite("epsilon_mode", &FlowGraphParams::epsilonMode, "EpsilonMode.TWO_THIRDS or EXPLICIT.");
  c.def_readwrite("epsilon", &FlowGraphParams::epsilon, "ε for EpsilonMode.EXPLICIT, in [a, b].");
  c.def_readwrite("min_node_gap", &FlowGraphParams::minNodeGap,
                  "Pairs of one state at most this many node steps apart are no candidates (default 8).");
  c.def_readwrite("threads", &FlowGraphParams::threads, "Worker threads of the cost matrix; 0 = all cores.");
  c.def("validate", &FlowGraphParams::validate, "ValueError naming the setting and its range.");

  m.def(
      "same_magnitude_weights",
      [](const py::sequence& groups, int threads) {
        const auto p = groupPointers(groups);
        py::gil_scoped_release release;
        const FlowWeights w = sameMagnitudeWeights(p, threads);
        return std::make_pair(w.alpha, w.beta);
      },
      py::arg("groups"), py::arg("threads") = 0,
      "(alpha, beta) of eq. 9 bringing the mean squared differences of velocity, density and "
      "temperature over all pairs of groups to the same magnitude (§4.3).");
  m.def(
      "same_magnitude_weights_of_files",
      [](const py::sequence& files, int threads) {
        const NodeFiles nodes = nodeFiles(files);
        py::gil_scoped_release release;
        const FlowWeights w = sameMagnitudeWeights(nodes, threads);
        return std::make_pair(w.alpha, w.beta);
      },
      py::arg("files"), py::arg("threads") = 0,
      "same_magnitude_weights() of every group of the states' PathlineFiles (in state order), "
      "the same bits, reading 32 groups at a time (two passes).");
  m.def(
      "cost_matrix",
      [](const py::sequence& groups, const FlowGraphParams& params) {
        const auto p = groupPointers(groups);
        CostMatrix c;
        {
          py::gil_scoped_release release;
          c = computeCostMatrix(p, params);
        }
        return costArray(c);
      },
      py::arg("groups"), py::arg("params") = FlowGraphParams(),
      "C of eq. 9-10, (N, N) float64, for PathlineGroups ordered state by state and "
      "chronologically (all must share one layout). Uses params.alpha, beta and threads.");
  m.def(
      "cost_matrix_of_files",
      [](const py::sequence& files, const FlowGraphParams& params, double rowBlockMb, int columnNodes) {
        const NodeFiles nodes = nodeFiles(files);
        const CostStreamParams stream = streamParams(rowBlockMb, columnNodes);
        CostMatrix c;
        CostStreamStats stats;
        {
          py::gil_scoped_release release;
          c = computeCostMatrix(nodes, params, nullptr, stream, &stats);
        }
        return py::make_tuple(costArray(c), statsDict(stats));
      },
      py::arg("files"), py::arg("params") = FlowGraphParams(), py::arg("row_block_mb") = 600.0,
      py::arg("column_nodes") = 32,
      "(C, stats): cost_matrix() of every group of the states' PathlineFiles (in state order), the "
      "same bits, streamed: rows in blocks of row_block_mb, columns in blocks of column_nodes. "
      "stats: row_nodes, column_nodes, group_reads, read_seconds, seconds.");
}

void bindJob(py::module_& m) {
  py::class_<CostMatrixJob> j(m, "CostMatrixJob",
                              "cost_matrix() for a worker thread: run() computes (GIL released), another "
                              "thread may read progress or call cancel().");
  j.def(py::init([](const py::sequence& groups, const FlowGraphParams& params) {
          auto job = std::make_unique<CostMatrixJob>();
          job->groups = groups;
          job->pointers = groupPointers(groups);
          job->params = params;
          return job;
        }),
        py::arg("groups"), py::arg("params") = FlowGraphParams());
  j.def_static(
      "of_files",
      [](const py::sequence& files, const FlowGraphParams& params, double rowBlockMb, int columnNodes) {
        auto job = std::make_unique<CostMatrixJob>();
        job->groups = files;
        job->files = std::make_unique<NodeFiles>(nodeFiles(files));
        job->stream = streamParams(rowBlockMb, columnNodes);
        job->params = params;
        return job;
      },
      py::arg("files"), py::arg("params") = FlowGraphParams(), py::arg("row_block_mb") = 600.0,
      py::arg("column_nodes") = 32,
      "A job streaming the groups of the states' PathlineFiles (see cost_matrix_of_files).");
  j.def(
      "run",
      [](CostMatrixJob& job) {
        CostMatrix c;
        {
          py::gil_scoped_release release;
          c = job.files ? computeCostMatrix(*job.files, job.params, &job.progress, job.stream, &job.stats)
                        : computeCostMatrix(job.pointers, job.params, &job.progress);
        }
        job.finished = !job.progress.cancel.load();
        if (job.finished) job.cost = std::move(c);
        return job.finished;
      },
      "Computes C; False when cancel() was called (no result then). ValueError on bad groups or params.");
  j.def("cancel", [](CostMatrixJob& job) { job.progress.cancel = true; }, "Thread-safe: run() stops early.");
  j.def_property_readonly("progress", [](const CostMatrixJob& job) { return job.progress.fraction(); },
                          "Finished fraction in [0, 1].");
  j.def_property_readonly("stats", [](const CostMatrixJob& job) { return statsDict(job.stats); },
                          "A streamed run's row_nodes, column_nodes, group_reads, read_seconds, seconds.");
  j.def_property_readonly(
      "cost",
      [](const CostMatrixJob& job) {
        if (!job.finished) throw py::value_error("the cost matrix is not computed (run() first, not cancelled)");
        return costArray(job.cost);
      },
      "C, (N, N) float64, after a run() that returned True.");
}

/// FlowGraph.transitions() and select_transitions() as a dict.
py::dict selectionDict(const TransitionSelection& s) {
  const auto& c = s.candidates;
  py::dict d;
  d["row"] = arrayFrom<int>(c.size(), [&](std::size_t k) { return c[k].row; });
  d["col"] = arrayFrom<int>(c.size(), [&](std::size_t k) { return c[k].col; });
  d["cost"] = arrayFrom<double>(c.size(), [&](std::size_t k) { return c[k].cost; });
  d["kept"] = arrayFrom<bool>(c.size(), [&](std::size_t k) { return c[k].kept; });
  d["a"] = s.a;
  d["b"] = s.b;
  d["epsilon"] = s.epsilon;
  d["blocks_per_side"] = s.blocksPerSide;
  return d;
}

void bindGraph(py::module_& m) {
  py::class_<FlowGraph> g(m, "FlowGraph",
                          "The flow graph of §4.3: temporal edges (eq. 8), kept transitions (eq. 11) read as "
                          "i -> j + 1, nodes that cannot reach a cycle or the largest strongly "
                          "connected component (traps) pruned.");
  g.def_static(
      "build",
      [](const py::object& cost, const std::vector<int>& counts, const FlowGraphParams& params) {
        const CostMatrix c = toCost(cost);
        py::gil_scoped_release release;
        return FlowGraph::build(c, counts, params);
      },
      py::arg("cost"), py::arg("state_node_counts"), py::arg("params") = FlowGraphParams(),
      "The graph of cost matrix `cost` (N, N) whose nodes are state_node_counts[0] nodes of state 0, "
      "then those of state 1, ... ValueError if a state's first node is pruned.");
  g.def_property_readonly("node_count", &FlowGraph::nodeCount, "N, pruned nodes included.");
  g.def_property_readonly("state_count", &FlowGraph::stateCount, "Number of states.");
  g.def_property_readonly("state_node_counts", &FlowGraph::stateNodeCounts, "Nodes per state (before pruning).");
  g.def_property_readonly("pruned_per_state", &FlowGraph::prunedPerState, "Pruned nodes per state.");
  g.def_property_readonly(
      "node_states", [](const FlowGraph& f) { return arrayFrom<int>(std::size_t(f.nodeCount()), [&](std::size_t n) { return f.state(int(n)); }); },
      "State of every node, (N,) int32.");
  g.def_property_readonly(
      "node_steps", [](const FlowGraph& f) { return arrayFrom<int>(std::size_t(f.nodeCount()), [&](std::size_t n) { return f.step(int(n)); }); },
      "Step of every node inside its state, (N,) int32.");
  g.def_property_readonly(
      "pruned", [](const FlowGraph& f) { return arrayFrom<bool>(std::size_t(f.nodeCount()), [&](std::size_t n) { return f.pruned(int(n)); }); },
      "True for the pruned nodes, (N,) bool.");
  g.def_property_readonly(
      "stays_in_state",
      [](const FlowGraph& f) { return arrayFrom<bool>(std::size_t(f.nodeCount()), [&](std::size_t n) { return f.staysInState(int(n)); }); },
      "True where a walk can stay in the node's state forever, (N,) bool.");
  g.def(
      "out_degree",
      [](const FlowGraph& f, int node) {
        if (node < 0 || node >= f.nodeCount())
          throw py::value_error("node must be in [0, " + std::to_string(f.nodeCount() - 1) + "]");
        return f.outDegree(node);
      },
      py::arg("node"), "d(V_i) of §5.1.");
  g.def("reachable_states", &FlowGraph::reachableStates, py::arg("state"),
        "States a walk from the first node of `state` can ever visit (a target outside is never reached).");
  g.def(
      "edges",
      [](const FlowGraph& f) {
        std::vector<int> from;
        for (int n = 0; n < f.nodeCount(); ++n)
          for (int k = 0; k < f.outDegree(n); ++k) from.push_back(n);
        const FlowEdge* e = f.outEdges(0).begin();
        py::dict d;
        d["from"] = array1D(from);
        d["to"] = arrayFrom<int>(from.size(), [&](std::size_t k) { return e[k].to; });
        d["cost"] = arrayFrom<double>(from.size(), [&](std::size_t k) { return e[k].cost; });
        d["temporal"] = arrayFrom<bool>(from.size(), [&](std::size_t k) { return e[k].temporal; });
        return d;
      },
      "Every edge of the pruned graph: dict of (E,) arrays from, to, cost, temporal (by source node).");
  g.def(
      "transitions", [](const FlowGraph& f) { return selectionDict(f.transitions()); },
      "The block candidates (row, col, cost, kept arrays; edge row -> col + 1), a, b, ε and M (§4.3).");
  m.def(
      "select_transitions",
      [](const py::object& cost, const std::vector<int>& counts, const FlowGraphParams& params) {
        const CostMatrix c = toCost(cost);
        TransitionSelection s;
        {
          py::gil_scoped_release release;
          s = selectTransitions(c, counts, params);
        }
        return selectionDict(s);
      },
      py::arg("cost"), py::arg("state_node_counts"), py::arg("params") = FlowGraphParams(),
      "The candidates of eq. 11 without building the graph (FlowGraph.transitions() of a graph "
      "that could not be built: a and b tell which ε to give). ValueError on bad params.");

  m.def(
      "cost_matrix_image",
      [](const py::object& cost, const FlowGraph& graph, int size) {
        const CostMatrix c = toCost(cost);
        RgbImage img;
        {
          py::gil_scoped_release release;
          img = costMatrixImage(c, graph.transitions(), graph.stateNodeCounts(), size);
        }
        py::array_t<std::uint8_t> a({py::ssize_t(img.height), py::ssize_t(img.width), py::ssize_t(3)});
        std::memcpy(a.mutable_data(), img.pixels.data(), img.pixels.size());
        return a;
      },
      py::arg("cost"), py::arg("graph"), py::arg("size") = 512,
      "Figure 4: (size, size, 3) uint8 RGB, top row = node 0; grey cost (darker = lower), blue "
      "filtered candidates, yellow kept transitions, red lines between states.");
}

void bindWalk(py::module_& m) {
  py::class_<RandomWalk> w(m, "RandomWalk", "A seeded random walk on a FlowGraph (§5.1).");
  w.def(py::init<const FlowGraph&, std::uint64_t, WalkBias, double, int, int>(), py::arg("graph"), py::arg("seed"),
        py::arg("bias") = WalkBias::Uniform, py::arg("gamma") = 0.875, py::arg("start_state") = 0,
        py::arg("transition_hold") = 0, py::keep_alive<1, 2>(),
        "Starts at the first node of start_state. transition_hold: node steps on temporal edges "
        "after each transition (the transition state; the pathlines' lifetime L; 0: none).");
  w.def_property_readonly("current", &RandomWalk::current, "The node visited now.");
  w.def_property_readonly("transition_hold", &RandomWalk::transitionHold, "H, node steps (0: none).");
  w.def_property_readonly("hold_remaining", &RandomWalk::holdRemaining,
                          "Temporal steps left before the walk may take a transition (0: free).");
  w.def_property_readonly("forced_transitions", &RandomWalk::forcedTransitions,
                          "Transitions taken inside a hold (the node had no temporal edge nor long transition).");
  w.def(
      "target_distance",
      [](const RandomWalk& walk, int node, int state, int hold) {
        if (node < 0 || node >= walk.graph().nodeCount())
          throw py::value_error("node must be in [0, " + std::to_string(walk.graph().nodeCount() - 1) + "]");
        if (state < 0 || state >= walk.graph().stateCount())
          throw py::value_error("state must be in [0, " + std::to_string(walk.graph().stateCount() - 1) + "]");
        if (hold < 0 || hold > walk.transitionHold())
          throw py::value_error("hold must be in [0, " + std::to_string(walk.transitionHold()) + "]");
        return walk.targetDistance(node, state, hold);
      },
      py::arg("node"), py::arg("state"), py::arg("hold") = 0,
      "Fewest node steps from node, with `hold` steps of the transition state left, to the nodes "
      "of `state` a walk can stay in (-1: unreachable).");
  w.def(
      "temporal_run",
      [](const RandomWalk& walk, int node) {
        if (node < 0 || node >= walk.graph().nodeCount())
          throw py::value_error("node must be in [0, " + std::to_string(walk.graph().nodeCount() - 1) + "]");
        return walk.temporalRun(node);
      },
      py::arg("node"),
        "Temporal edges that follow node before its state's time line ends.");
  w.def("next", &RandomWalk::next, py::arg("target_state") = -1,
        "Follows one edge (steered to target_state unless -1) and returns the new node.");
  w.def(
      "run",
      [](RandomWalk& walk, const py::object& targets) {
        const Int64ArrayC t = Int64ArrayC::ensure(targets);
        if (!t || t.ndim() != 1) throw py::value_error("targets must be a 1-D integer array");
        std::vector<int> nodes(std::size_t(t.size()));
        const std::vector<long long> tv(t.data(), t.data() + t.size());
        {
          py::gil_scoped_release release;
          for (std::size_t k = 0; k < nodes.size(); ++k)
            nodes[k] = walk.next(int(std::max(-2LL, std::min(tv[k], 1LL << 30))));  // next() checks the range
        }
        return array1D(nodes);
      },
      py::arg("targets"), "next(targets[k]) for every k (-1: no target); the nodes visited, (K,) int32.");
  w.def(
      "edge_probabilities",
      [](const RandomWalk& walk, int node, int target) {
        return array1D(walk.edgeProbabilities(node, target));
      },
      py::arg("node"), py::arg("target_state") = -1,
      "Probability of each out-edge of node (FlowGraph.edges order), eq. 12 or §5.1 target rule.");
}

}  // namespace

void bindFlowgraphGraph(py::module_& m) {
  bindParams(m);
  bindJob(m);
  bindGraph(m);
  bindWalk(m);
}

}  // namespace plume::bindings
