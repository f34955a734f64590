/// \file flow_graph.cpp
/// Building the flow graph (§4.3): edges, then the pruning of every node that cannot reach a
/// cycle (a walk through it would end) or the main strongly connected component (a walk into it
/// would be trapped), then the nodes from which a walk can stay in its state.

#include "flowgraph/flow_graph.h"

#include "core/format.h"
#include "flowgraph/state_nodes.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

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
    // Stable: edges to one target (if any) keep their order with every standard library.
    std::stable_sort(lists[n].begin(), lists[n].end(),
                     [](const FlowEdge& a, const FlowEdge& b) { return a.to < b.to; });
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
  std::vector<int> predecessors(static_cast<std::size_t>(predecessorBegin[n]));
  std::vector<int> fill(predecessorBegin.begin(), predecessorBegin.end() - 1);
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

/// Strongly connected components of the alive nodes over edges between alive nodes (Tarjan's
/// algorithm without recursion): a component id per node, -1 for the nodes not alive.
std::vector<int> strongComponents(const EdgeLists& g, const std::vector<char>& alive) {
  const int n = int(alive.size());
  std::vector<int> index(std::size_t(n), -1), low(std::size_t(n), 0), component(std::size_t(n), -1), open;
  std::vector<char> onStack(std::size_t(n), 0);
  std::vector<std::pair<int, int>> calls;  // (node, its next edge to look at)
  int counter = 0, components = 0;
  auto visit = [&](int v) {
    index[std::size_t(v)] = low[std::size_t(v)] = counter++;
    open.push_back(v);
    onStack[std::size_t(v)] = 1;
    calls.push_back({v, g.begin[std::size_t(v)]});
  };
  for (int root = 0; root < n; ++root) {
    if (!alive[std::size_t(root)] || index[std::size_t(root)] >= 0) continue;
    visit(root);
    while (!calls.empty()) {
      const int v = calls.back().first;
      const int k = calls.back().second;
      if (k < g.begin[std::size_t(v) + 1]) {
        ++calls.back().second;
        const int w = g.edges[std::size_t(k)].to;
        if (!alive[std::size_t(w)]) continue;
        if (index[std::size_t(w)] < 0) visit(w);
        else if (onStack[std::size_t(w)]) low[std::size_t(v)] = std::min(low[std::size_t(v)], index[std::size_t(w)]);
        continue;
      }
      if (low[std::size_t(v)] == index[std::size_t(v)]) {
        int w;
        do {
          w = open.back();
          open.pop_back();
          onStack[std::size_t(w)] = 0;
          component[std::size_t(w)] = components;
        } while (w != v);
        ++components;
      }
      calls.pop_back();
      if (!calls.empty()) {
        const int u = calls.back().first;
        low[std::size_t(u)] = std::min(low[std::size_t(u)], low[std::size_t(v)]);
      }
    }
  }
  return component;
}

/// The alive nodes that can reach the largest strongly connected component of their part of
/// the graph (weakly connected component; ties: the component of the lowest node). A node that
/// cannot is a trap: a walk entering it never comes back, e.g. a short loop at the end of a
/// state whose only exits lead back into it would replay the same few groups forever. Keeping
/// only the nodes that reach the main component (as motion graphs keep their largest strongly
/// connected component, Kovar et al. 2002) leaves every node an out-edge towards it.
std::vector<char> reachingMainComponent(const EdgeLists& g, const std::vector<char>& alive) {
  const std::size_t n = alive.size();
  const std::vector<int> scc = strongComponents(g, alive);
  // Weakly connected parts (union-find over the alive edges).
  std::vector<int> part(n);
  for (std::size_t m = 0; m < n; ++m) part[m] = int(m);
  auto root = [&](int m) {
    while (part[std::size_t(m)] != m) m = part[std::size_t(m)] = part[std::size_t(part[std::size_t(m)])];
    return m;
  };
  std::vector<int> sccSize(n, 0);
  for (std::size_t m = 0; m < n; ++m) {
    if (!alive[m]) continue;
    ++sccSize[std::size_t(scc[m])];
    for (int k = g.begin[m]; k < g.begin[m + 1]; ++k) {
      const int to = g.edges[std::size_t(k)].to;
      if (alive[std::size_t(to)]) part[std::size_t(root(int(m)))] = root(to);
    }
  }
  // The largest component of each part (scanned by node: ties go to the lowest node).
  std::vector<int> mainOf(n, -1);
  for (std::size_t m = 0; m < n; ++m) {
    if (!alive[m]) continue;
    int& best = mainOf[std::size_t(root(int(m)))];
    if (best < 0 || sccSize[std::size_t(scc[m])] > sccSize[std::size_t(best)]) best = scc[m];
  }
  // Backwards from the main components over the alive edges.
  std::vector<std::vector<int>> predecessors(n);
  for (std::size_t m = 0; m < n; ++m)
    if (alive[m])
      for (int k = g.begin[m]; k < g.begin[m + 1]; ++k)
        if (alive[std::size_t(g.edges[std::size_t(k)].to)])
          predecessors[std::size_t(g.edges[std::size_t(k)].to)].push_back(int(m));
  std::vector<char> keep(n, 0);
  std::vector<int> stack;
  for (std::size_t m = 0; m < n; ++m)
    if (alive[m] && scc[m] == mainOf[std::size_t(root(int(m)))]) {
      keep[m] = 1;
      stack.push_back(int(m));
    }
  while (!stack.empty()) {
    const int m = stack.back();
    stack.pop_back();
    for (int p : predecessors[std::size_t(m)])
      if (!keep[std::size_t(p)]) {
        keep[std::size_t(p)] = 1;
        stack.push_back(p);
      }
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

  // Prune what cannot reach a cycle, then the traps (what cannot reach the main strongly
  // connected component); keep the edges between the nodes left.
  const std::vector<char> alive = reachingMainComponent(
      all, reachingCycle(all, std::vector<char>(std::size_t(n), 1), [](int, const FlowEdge&) { return true; }));
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
