#pragma once
/// \file random_walk.h
/// Random walks on a flow graph ([Graph Fire Synthesis] §5.1): from the first node of a
/// state, one edge per node step, uniform, with temporal bias γ (eq. 12), or steered to a
/// target state; seeded, so the same seed gives the same walk.

#include "core/rng.h"
#include "flowgraph/flow_graph.h"
#include "flowgraph/target_distance.h"

#include <cstdint>
#include <vector>

namespace plume {

/// How the next edge is drawn when no target state steers the walk (§5.1).
enum class WalkBias {
  Uniform,   ///< p(i, j) = 1 / d(V_i)
  Temporal,  ///< eq. 12: γ on the temporal edge, (1 − γ) / (d(V_i) − 1) on each other edge
};

/// A walk V_1, V_2, ... on a FlowGraph (§5.1). The graph must outlive the walk.
///
/// Transition state (§5, results: "When the synthesizer reaches a transition edge, it enters the
/// transition state ... [it] will not leave the transition state until these existing particles
/// are dissipated"). With a hold of H > 0 node steps (the synthesis passes the pathlines'
/// lifetime L), the H steps after a transition follow temporal edges only, so the particles
/// emitted before a transition are gone before the next one: transitions are more than H steps
/// apart. To make the hold possible, a free step also drops the transitions into a node whose
/// temporal run (the temporal edges that follow it) is shorter than H, whenever the node has
/// another edge; eq. 12 and the target rule then apply to the edges left (d(V_i) counts them).
/// Only a node without temporal edge whose every transition is short, a target state reachable
/// through short transitions only, or a time line that would leave the target state's goal
/// (see edgeProbabilities()) forces an early transition (counted by forcedTransitions()).
class RandomWalk {
 public:
  /// Starts at the first node of `startState` (§5.1 "starting at node k = 0"). Throws
  /// std::invalid_argument for a start state out of range, γ outside [0, 1] (the paper's
  /// 0 < γ < 1 plus the two limits: γ = 1 always follows the temporal edge where there is one,
  /// γ = 0 never unless it is the only edge) or a transition hold outside [0, K − 1], K the
  /// node count of the shortest state (a longer hold could never be kept).
  RandomWalk(const FlowGraph& graph, std::uint64_t seed, WalkBias bias = WalkBias::Uniform, double gamma = 0.875,
             int startState = 0, int transitionHold = 0);

  const FlowGraph& graph() const { return *mGraph; }
  /// H, node steps (0: transitions may follow each other at any step).
  int transitionHold() const { return mHold; }
  /// Temporal steps still to take before the walk may leave its state's time line (0: free).
  int holdRemaining() const { return mHoldLeft; }
  /// Transitions taken while holding, because the node had no temporal edge nor long transition.
  long long forcedTransitions() const { return mForced; }
  /// D(node, h) for target state `state` (target_distance.h): the fewest node steps from
  /// `node` with `hold` hold steps left (0: a free step) to W' (see edgeProbabilities()), the
  /// strict distance where finite, else the loose one; −1 where W' cannot be reached.
  int targetDistance(int node, int state, int hold = 0) const {
    int d = mTargets(state, node, hold, true);
    if (d == TargetDistances::kFar) d = mTargets(state, node, hold, false);
    return d == TargetDistances::kFar ? -1 : d;
  }
  /// Temporal edges that follow `node` before its state's time line ends (or is pruned).
  int temporalRun(int node) const { return mRun[std::size_t(node)]; }

  /// The node visited now.
  int current() const { return mCurrent; }

  /// Probability of each out-edge of `node` (in FlowGraph::outEdges order) for a free step (not
  /// holding; with a hold, short transitions are dropped first, see the class comment) when
  /// steering to `targetState` (−1: none).
  ///
  /// Target state W (§5.1: "the edge probabilities are computed depending on how far the
  /// current visited node is from the target state"). The goal is W' = the nodes of W from which
  /// a walk can stay in W forever (FlowGraph::staysInState; all of W if none can), so that "once
  /// a target state is reached, the traversal will remain there" holds on any graph. With
  /// δ(n) = D(n, 0) the fewest node steps from n to W', the holds of the transition state
  /// counted (target_distance.h): outside W' a free step takes, uniformly, one of the edges on a
  /// shortest path (D of the walk state it leads to = δ(node) − 1), so it reaches W' in δ steps
  /// wherever it starts
  /// (taking only edges straight into W, a walk can wander for ever in a part of the graph
  /// whose exits to W are several edges away); inside W' it takes the edges that stay in W'
  /// (δ = 0) with the bias below (eq. 12 or uniform) among them. Where W cannot be reached
  /// (δ = ∞), the target is ignored.
  ///
  /// Without a target: WalkBias::Uniform gives 1/d(V_i); WalkBias::Temporal gives eq. 12 (γ on
  /// the temporal edge, (1 − γ)/(d − 1) on the others; d = 1 gives 1; a node without temporal
  /// edge, e.g. the last of its state, shares 1 uniformly among its transitions).
  std::vector<double> edgeProbabilities(int node, int targetState = -1) const;

  /// Follows one edge drawn with edgeProbabilities(current(), targetState), or the temporal edge
  /// while holding, and returns the new node. The target may change at every step (the artist keys it). Throws
  /// std::invalid_argument for a target state outside [−1, states − 1].
  int next(int targetState = -1);

 private:
  void probabilities(int node, int targetState, std::vector<double>& p) const;
  /// Eq. 12 (or uniform) over the edges `take` admits: the others get 0.
  template <class Take>
  void biased(const FlowGraph::EdgeRange& edges, const Take& take, std::vector<double>& p) const;
  /// False when a held step from → to would leave the target's goal W' or put it out of reach:
  /// the hold then ends early (a forced transition), since the artist's key comes first.
  bool keepsTarget(int from, int to, int holdAfter, int targetState) const;
  /// False for an edge a free step drops under the hold (a transition with a short run).
  bool longEnough(const FlowEdge& e) const { return e.temporal || mRun[std::size_t(e.to)] >= mHold; }

  const FlowGraph* mGraph;
  Rng mRng;
  WalkBias mBias;
  double mGamma;
  int mCurrent;
  int mHold = 0;
  int mHoldLeft = 0;
  long long mForced = 0;
  std::vector<int> mRun;  ///< temporalRun() of every node
  TargetDistances mTargets;  ///< D of every walk state to each target state's goal W'

  std::vector<double> mScratch;
};

}  // namespace plume
