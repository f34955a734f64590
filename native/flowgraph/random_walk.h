#pragma once
/// \file random_walk.h
/// Random walks on a flow graph (graph_fire_synthesis.txt §5.1): from the first node of a
/// state, one edge per node step, uniform, with temporal bias γ (eq. 12), or steered to a
/// target state; seeded, so the same seed gives the same walk.

#include "core/rng.h"
#include "flowgraph/flow_graph.h"

#include <cstdint>
#include <vector>

namespace plume {

/// How the next edge is drawn when no target state steers the walk (§5.1).
enum class WalkBias {
  Uniform,   ///< p(i, j) = 1 / d(V_i)
  Temporal,  ///< eq. 12: γ on the temporal edge, (1 − γ) / (d(V_i) − 1) on each other edge
};

/// A walk V_1, V_2, ... on a FlowGraph (§5.1). The graph must outlive the walk.
class RandomWalk {
 public:
  /// Starts at the first node of `startState` (§5.1 "starting at node k = 0"). Throws
  /// std::invalid_argument for a start state out of range or γ outside [0, 1] (the paper's
  /// 0 < γ < 1 plus the two limits: γ = 1 always follows the temporal edge where there is one,
  /// γ = 0 never unless it is the only edge).
  RandomWalk(const FlowGraph& graph, std::uint64_t seed, WalkBias bias = WalkBias::Uniform, double gamma = 0.875,
             int startState = 0);

  /// The node visited now.
  int current() const { return mCurrent; }

  /// Probability of each out-edge of `node` (in FlowGraph::outEdges order) when steering to
  /// `targetState` (−1: none). With a target state W (§5.1): if some edge leads into W, those
  /// edges share the probability uniformly (p = 1/k, k edges into W), otherwise the biased rule
  /// below applies. Plume narrows "into W" to the nodes of W from which a walk can stay in W
  /// forever (FlowGraph::staysInState) whenever such an edge exists, so that "once a target
  /// state is reached, the traversal will remain there" holds on any graph: from such a node an
  /// edge to another one always exists. Without a target: WalkBias::Uniform gives 1/d(V_i);
  /// WalkBias::Temporal gives eq. 12 (γ on the temporal edge, (1 − γ)/(d − 1) on the others;
  /// d = 1 gives 1; a node without temporal edge, e.g. the last of its state, shares 1
  /// uniformly among its transitions).
  std::vector<double> edgeProbabilities(int node, int targetState = -1) const;

  /// Follows one edge drawn with edgeProbabilities(current(), targetState) and returns the new
  /// node. The target may change at every step (the artist keys it). Throws
  /// std::invalid_argument for a target state outside [−1, states − 1].
  int next(int targetState = -1);

 private:
  void probabilities(int node, int targetState, std::vector<double>& p) const;

  const FlowGraph* mGraph;
  Rng mRng;
  WalkBias mBias;
  double mGamma;
  int mCurrent;
  std::vector<double> mScratch;
};

}  // namespace plume
