#pragma once
/// \file flow_graph.h
/// The flow graph G = (V, E) of [Graph Fire Synthesis] §4.3: one node per pathline group
/// (state, step), temporal edges k → k+1 inside a state (eq. 8) and the kept transition edges
/// (eq. 11), with every node that cannot continue forever, or from which a walk could never
/// come back to the main part of the graph, pruned: a random walk (§5.1) never ends nor gets
/// trapped.
///
/// Edge direction. c_ij compares the groups i and j; a walk emits one group per node step. A
/// candidate (i, j) becomes the edge i → j + 1: after emitting i, continue with the successor of
/// j instead of the successor of i. Since groups i and j are alike, the emitted sequence
/// ..., i, j+1, j+2, ... looks locally like the original ..., j, j+1, j+2, ... (the motion-graph
/// reading), whereas i → j would emit two near copies of one group in a row (a stutter). C is
/// symmetric, so the mirrored block yields j → i + 1: both directions exist. Temporal edges are
/// always there between surviving nodes, so a walk restricted to them replays a state as it was
/// simulated.

#include "flowgraph/cost_matrix.h"
#include "flowgraph/flow_graph_params.h"
#include "flowgraph/transitions.h"

#include <vector>

namespace plume {

/// An out-edge of a node (§4.3).
struct FlowEdge {
  int to = 0;            ///< target node
  double cost = 0.0;     ///< c_ij of the candidate (transition) or c_k,k+1 (temporal)
  bool temporal = false; ///< eq. 8 edge k → k+1 of one state; otherwise a transition (eq. 11)
};

/// The flow graph of §4.3 over all states. Node ids are the rows of the cost matrix (state by
/// state, chronologically); pruned nodes keep their id but have no edges in or out.
class FlowGraph {
 public:
  /// Out-edges of one node, sorted by target.
  struct EdgeRange {
    const FlowEdge* first;
    const FlowEdge* last;
    const FlowEdge* begin() const { return first; }
    const FlowEdge* end() const { return last; }
    int size() const { return int(last - first); }
  };

  FlowGraph() = default;

  /// §4.3: temporal edges (eq. 8), transitions from selectTransitions() (eq. 11, read as
  /// row → col + 1), then pruning: nodes of out-degree 0 are removed with the edges into them,
  /// repeatedly, until every node left has an out-edge, i.e. exactly the nodes that can reach a
  /// cycle remain; then the traps: in each weakly connected part of the graph, the nodes that
  /// cannot reach its largest strongly connected component (a walk entering them could never
  /// leave, e.g. a short loop at the end of a state whose only exit leads back into it, replayed
  /// forever; motion graphs keep their largest strongly connected component for the same
  /// reason, Kovar et al. 2002). Every node left has an out-edge towards that component.
  /// Throws std::invalid_argument for invalid params or counts, or when the first node of a
  /// state is pruned (no walk could start there; the message names the states and says to add
  /// states, lower block_size or raise epsilon).
  static FlowGraph build(const CostMatrix& cost, const std::vector<int>& stateNodeCounts,
                         const FlowGraphParams& params);

  /// N, pruned nodes included.
  int nodeCount() const { return int(mState.size()); }
  /// Number of states.
  int stateCount() const { return int(mOffsets.size()) - 1; }
  /// The state of a node.
  int state(int node) const { return mState[std::size_t(node)]; }
  /// The node's step inside its state (0 = the state's first group).
  int step(int node) const { return node - mOffsets[std::size_t(state(node))]; }
  /// Node id of (state, step).
  int node(int state, int step) const { return mOffsets[std::size_t(state)] + step; }
  /// Nodes of a state before pruning.
  int stateNodeCount(int state) const { return mOffsets[std::size_t(state) + 1] - mOffsets[std::size_t(state)]; }
  /// stateNodeCount() of every state, in order (the counts the graph was built from).
  std::vector<int> stateNodeCounts() const {
    std::vector<int> c;
    for (int s = 0; s < stateCount(); ++s) c.push_back(stateNodeCount(s));
    return c;
  }
  /// True when the node was pruned (it could not reach a cycle, or it was a trap).
  bool pruned(int node) const { return mPruned[std::size_t(node)] != 0; }
  /// Pruned nodes per state.
  const std::vector<int>& prunedPerState() const { return mPrunedPerState; }
  /// Out-edges of a node (none for a pruned node, at least one otherwise).
  EdgeRange outEdges(int node) const {
    const FlowEdge* base = mEdges.data();
    return {base + mEdgeBegin[std::size_t(node)], base + mEdgeBegin[std::size_t(node) + 1]};
  }
  /// d(V_i) of §5.1.
  int outDegree(int node) const { return outEdges(node).size(); }
  /// All edges of the pruned graph.
  int edgeCount() const { return int(mEdges.size()); }
  /// Temporal edges of the pruned graph.
  int temporalEdgeCount() const;
  /// True when a walk can stay inside the node's state forever from it (it reaches a cycle of
  /// edges inside the state): the nodes a target-state walk aims for (random_walk.h).
  bool staysInState(int node) const { return mStays[std::size_t(node)] != 0; }
  /// The states, ascending, that a walk from the first node of `state` can ever visit (§5.1:
  /// a target state outside them is never reached, so a caller can warn about it).
  std::vector<int> reachableStates(int state) const;
  /// The candidates and kept transitions before pruning (Figure 4).
  const TransitionSelection& transitions() const { return mTransitions; }

 private:
  std::vector<int> mOffsets;  // first node of each state, then N
  std::vector<int> mState;
  std::vector<char> mPruned;
  std::vector<char> mStays;
  std::vector<int> mPrunedPerState;
  std::vector<int> mEdgeBegin;  // CSR: edges of node n are mEdges[mEdgeBegin[n] .. mEdgeBegin[n+1])
  std::vector<FlowEdge> mEdges;
  TransitionSelection mTransitions;
};

}  // namespace plume
