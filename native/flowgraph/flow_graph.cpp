/// \file flow_graph.cpp
/// Building the flow graph (§4.3): edges, then the pruning of every node that cannot reach a
/// cycle (a walk through it would end), then the nodes from which a walk can stay in its state.

#include "flowgraph/flow_graph.h"

#include "core/format.h"
#include "flowgraph/state_nodes.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

/// Edges as a compressed row list: the edges of node n are edges[begin[n] .. begin[n + 1]).
struct EdgeLists {
  std::vector<int> begin;
  std::vector<FlowEdge> edges;
};

/// CSR of per-node edge lists, each sorted by target.
EdgeLists compress(std::vector<std::vector<FlowEdge>>& lists) {
  EdgeLists g;
  g.begin.assign(lists.size() + 1, 0);
  for (std::size_t n = 0; n < lists.size(); ++n) {
    std::sort(lists[n].begin(), lists[n].end(), [](const FlowEdge& a, const FlowEdge& b) { return a.to < b.to; });
    g.begin[n + 1] = g.begin[n] + int(lists[n].size());
    g.edges.insert(g.edges.end(), lists[n].begin(), lists[n].end());
  }
  return g;
}

/// Which of the `alive` nodes can reach a cycle through edges between alive nodes that
/// use(from, edge) accepts: nodes without such an out-edge are removed, with the edges into
/// them, until none is left (the remaining nodes all have an out-edge, so every walk on them is
/// infinite; a node that reaches a cycle always keeps its edge towards it).
template <typename Use>
std::vector<char> reachingCycle(const EdgeLists& g, const std::vector<char>& alive, const Use& use) {
  const std::size_t n = alive.size();
  std::vector<int> degree(n, 0), predecessorBegin(n + 1, 0);
  auto counted = [&](std::size_t from, const FlowEdge& e) {
    return alive[from] && alive[std::size_t(e.to)] && use(int(from), e);
  };
  for (std::size_t m = 0; m < n; ++m)
    for (int k = g.begin[m]; k < g.begin[m + 1]; ++k)
      if (counted(m, g.edges[std::size_t(k)])) {
        ++degree[m];
        ++predecessorBegin[std::size_t(g.edges[std::size_t(k)].to) + 1];
      }
  for (std::size_t m = 0; m < n; ++m) predecessorBegin[m + 1] += predecessorBegin[m];
  std::vector<int> predecessors(std::size_t(predecessorBegin[n])), fill(predecessorBegin.begin(), predecessorBegin.end() - 1);
  for (std::size_t m = 0; m < n; ++m)
    for (int k = g.begin[m]; k < g.begin[m + 1]; ++k)
      if (counted(m, g.edges[std::size_t(k)])) predecessors[std::size_t(fill[std::size_t(g.edges[std::size_t(k)].to)]++)] = int(m);

  std::vector<char> keep = alive;
  std::vector<int> dead;
  for (std::size_t m = 0; m < n; ++m)
    if (alive[m] && degree[m] == 0) dead.push_back(int(m));
  while (!dead.empty()) {
    const int m = dead.back();
    dead.pop_back();
    keep[std::size_t(m)] = 0;
    for (int k = predecessorBegin[std::size_t(m)]; k < predecessorBegin[std::size_t(m) + 1]; ++k)
      if (--degree[std::size_t(predecessors[std::size_t(k)])] == 0) dead.push_back(predecessors[std::size_t(k)]);
  }
  return keep;
}

}  // namespace

int FlowGraph::temporalEdgeCount() const {
  return int(std::count_if(mEdges.begin(), mEdges.end(), [](const FlowEdge& e) { return e.temporal; }));
}

std::vector<int> FlowGraph::reachableStates(int state) const {
  if (state < 0 || state >= stateCount())
    throw std::invalid_argument("state must be in [0, " + std::to_string(stateCount() - 1) + "] (got " +
                                std::to_string(state) + ")");
  std::vector<char> seen(mState.size(), 0), states(std::size_t(stateCount()), 0);
  std::vector<int> stack = {node(state, 0)};
  seen[std::size_t(stack.back())] = 1;
  while (!stack.empty()) {
    const int m = stack.back();
    stack.pop_back();
    states[std::size_t(mState[std::size_t(m)])] = 1;
    for (const FlowEdge& e : outEdges(m))
      if (!seen[std::size_t(e.to)]) {
        seen[std::size_t(e.to)] = 1;
        stack.push_back(e.to);
      }
  }
  std::vector<int> out;
  for (int s = 0; s < stateCount(); ++s)
    if (states[std::size_t(s)]) out.push_back(s);
  return out;
}

FlowGraph FlowGraph::build(const CostMatrix& cost, const std::vector<int>& stateNodeCounts,
                           const FlowGraphParams& params) {
  FlowGraph fg;
  fg.mTransitions = selectTransitions(cost, stateNodeCounts, params);  // checks params and counts
  fg.mOffsets = stateOffsets(stateNodeCounts);
  fg.mState = nodeStates(fg.mOffsets);
  const int n = cost.size();

  // Eq. 8 temporal edges and eq. 11 transitions (candidate (i, j) -> edge i -> j + 1).
  std::vector<std::vector<FlowEdge>> lists(static_cast<std::size_t>(n));
  for (int m = 0; m + 1 < n; ++m)
    if (fg.mState[std::size_t(m)] == fg.mState[std::size_t(m) + 1])
      lists[std::size_t(m)].push_back({m + 1, cost(m, m + 1), true});
  for (const TransitionCandidate& c : fg.mTransitions.candidates)
    if (c.kept) lists[std::size_t(c.row)].push_back({c.col + 1, c.cost, false});
  const EdgeLists all = compress(lists);

  // Prune what cannot reach a cycle; keep the edges between the nodes left.
  const std::vector<char> alive =
      reachingCycle(all, std::vector<char>(std::size_t(n), 1), [](int, const FlowEdge&) { return true; });
  for (int m = 0; m < n; ++m) {
    auto& l = lists[std::size_t(m)];
    if (!alive[std::size_t(m)]) l.clear();
    l.erase(std::remove_if(l.begin(), l.end(), [&](const FlowEdge& e) { return !alive[std::size_t(e.to)]; }),
            l.end());
  }
  EdgeLists kept = compress(lists);
  fg.mEdgeBegin = std::move(kept.begin);
  fg.mEdges = std::move(kept.edges);
  fg.mPruned.resize(std::size_t(n));
  for (int m = 0; m < n; ++m) fg.mPruned[std::size_t(m)] = !alive[std::size_t(m)];

  // Nodes from which a walk can stay in its own state (edges inside the state only).
  const EdgeLists pruned{fg.mEdgeBegin, fg.mEdges};
  fg.mStays = reachingCycle(pruned, alive, [&](int from, const FlowEdge& e) {
    return fg.mState[std::size_t(from)] == fg.mState[std::size_t(e.to)];
  });

  fg.mPrunedPerState.assign(std::size_t(fg.stateCount()), 0);
  for (int m = 0; m < n; ++m) fg.mPrunedPerState[std::size_t(fg.mState[std::size_t(m)])] += fg.pruned(m);
  std::string lost;
  for (int s = 0; s < fg.stateCount(); ++s)
    if (fg.pruned(fg.node(s, 0))) lost += (lost.empty() ? "" : ", ") + std::to_string(s);
  if (!lost.empty())
    throw std::invalid_argument(
        "no endless walk starts at the first node of state " + lost +
        ": every path from it reaches a dead end (too few transition edges). Add states, lower block_size (" +
        std::to_string(params.blockSize) + ") or raise epsilon (" + formatNumber(fg.mTransitions.epsilon) + ")");
  return fg;
}

}  // namespace plume
