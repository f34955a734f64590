#pragma once
/// \file target_distance.h
/// How far a walk is from a target state ([Graph Fire Synthesis] §5.1: "the edge
/// probabilities are computed depending on how far the current visited node is from the target
/// state"), counting the transition state of §5: after a transition the walk must follow
/// temporal edges for H node steps (random_walk.h). The distance is taken on the walk's own
/// state, (node, hold steps left), so a steered walk never overshoots the exit it is heading
/// for while it holds.

#include "flowgraph/flow_graph.h"

#include <limits>
#include <vector>

namespace plume {

/// D(state; node, h): the fewest node steps from node `node` with `h` hold steps left to the
/// goal W' of a target state, for every state of a FlowGraph. The walk's moves from (n, h):
/// h > 0: the temporal edge to (n + 1, h − 1); h = 0: the temporal edge to (n + 1, 0) or a
/// transition to (to, H). Where a held time line ends (h > 0, no temporal edge) the walk has to
/// break the hold: the strict distance has no move there (a steered walk avoids such paths),
/// the loose one lets any edge lead to (to, H) (used only where the strict one is infinite: W'
/// reachable by breaking a hold only). W' are the nodes of the state from which a walk can stay
/// in it forever (FlowGraph::staysInState; all its nodes if none can). Strictly, the walk has
/// arrived at (g, h) when g is in W' and so are the h nodes its hold still takes it through
/// (goalRun(g) >= h), so that a hold never ends outside the target; loosely, at any (g, h).
/// Breadth-first searches backwards from those walk states over all N (H + 1), two per target
/// state.
class TargetDistances {
 public:
  static constexpr int kFar = std::numeric_limits<int>::max();  ///< W' cannot be reached

  TargetDistances() = default;
  TargetDistances(const FlowGraph& graph, int hold);

  /// D(state; node, h), strict or loose, kFar where W' cannot be reached; h in [0, H].
  int operator()(int state, int node, int h, bool strict = true) const {
    return mDistance[std::size_t(state) * 2 + (strict ? 0 : 1)][index(node, h)];
  }
  /// True for the nodes of W' of `state`.
  bool inGoal(int state, int node) const { return goalRun(state, node) >= 0; }
  /// Temporal edges that follow `node` inside W' of `state` (−1: `node` is not in W').
  int goalRun(int state, int node) const { return mGoalRun[std::size_t(state)][std::size_t(node)]; }
  int hold() const { return mHold; }

 private:
  std::size_t index(int node, int h) const { return std::size_t(node) * std::size_t(mHold + 1) + std::size_t(h); }
  int mHold = 0;
  std::vector<std::vector<int>> mDistance;  ///< per target state strict, loose: N (H + 1) each
  std::vector<std::vector<int>> mGoalRun;   ///< per target state, goalRun() of every node
};

}  // namespace plume
