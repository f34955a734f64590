/// \file target_distance.cpp
/// The walk states (node, hold left), their moves reversed, and two breadth-first searches per
/// target state (strict and loose).

#include "flowgraph/target_distance.h"

#include <algorithm>
#include <queue>

namespace plume {

TargetDistances::TargetDistances(const FlowGraph& graph, int hold) : mHold(hold) {
  const int n = graph.nodeCount(), levels = hold + 1;
  const std::size_t states = std::size_t(n) * std::size_t(levels);
  // The moves of every walk state, reversed: strict (into[0]) and loose (into[1]).
  std::vector<std::vector<int>> into[2] = {std::vector<std::vector<int>>(states),
                                           std::vector<std::vector<int>>(states)};
  for (int node = 0; node < n; ++node) {
    int temporal = -1;
    for (const FlowEdge& e : graph.outEdges(node))
      if (e.temporal) temporal = e.to;
    for (int h = 0; h < levels; ++h) {
      const int from = int(index(node, h));
      if (h > 0 && temporal >= 0) {
        for (auto& moves : into) moves[index(temporal, h - 1)].push_back(from);
        continue;
      }
      for (const FlowEdge& e : graph.outEdges(node)) {
        const std::size_t to = e.temporal ? index(e.to, 0) : index(e.to, hold);
        if (h == 0) into[0][to].push_back(from);
        into[1][to].push_back(from);
      }
    }
  }
  for (int s = 0; s < graph.stateCount(); ++s) {
    std::vector<int> goal;
    for (bool mustStay : {true, false}) {
      for (int step = 0; step < graph.stateNodeCount(s); ++step) {
        const int node = graph.node(s, step);
        if (!graph.pruned(node) && (!mustStay || graph.staysInState(node))) goal.push_back(node);
      }
      if (!goal.empty()) break;
    }
    // goalRun: from the end of each time line backwards, along temporal edges inside W'.
    std::vector<int> run(std::size_t(n), -1);
    for (int node : goal) run[std::size_t(node)] = 0;
    for (int node = n - 1; node >= 0; --node) {
      if (run[std::size_t(node)] < 0) continue;
      for (const FlowEdge& e : graph.outEdges(node))
        if (e.temporal && run[std::size_t(e.to)] >= 0) run[std::size_t(node)] = run[std::size_t(e.to)] + 1;
    }
    for (int strict = 1; strict >= 0; --strict) {
      const auto& moves = into[strict ? 0 : 1];
      std::vector<int> dist(states, kFar);
      std::queue<int> open;
      for (int node : goal)
        for (int h = 0; h <= (strict ? std::min(hold, run[std::size_t(node)]) : hold); ++h) {
          dist[index(node, h)] = 0;
          open.push(int(index(node, h)));
        }
      while (!open.empty()) {
        const int v = open.front();
        open.pop();
        for (int u : moves[std::size_t(v)])
          if (dist[std::size_t(u)] == kFar) {
            dist[std::size_t(u)] = dist[std::size_t(v)] + 1;
            open.push(u);
          }
      }
      mDistance.push_back(std::move(dist));
    }
    mGoalRun.push_back(std::move(run));
  }
}

}  // namespace plume
