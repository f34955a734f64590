#pragma once
/// \file transitions.h
/// Transition edges of a flow graph ([Graph Fire Synthesis] §4.3): the minimum of each B×B
/// block of the cost matrix is a candidate; candidates with c < ε are kept (eq. 11), ε between
/// a = min and b = max of the candidates' costs, (2a + b)/3 by default.

#include "flowgraph/cost_matrix.h"
#include "flowgraph/flow_graph_params.h"

#include <vector>

namespace plume {

/// A candidate transition (§4.3): the minimum of its block of C, at entry (row, col). As a
/// graph edge it reads row → col + 1: "after emitting group `row`, continue with the successor
/// of the similar group `col`" (flow_graph.h).
struct TransitionCandidate {
  int row = 0;
  int col = 0;
  double cost = 0.0;  ///< c_row,col
  bool kept = false;  ///< cost < ε (eq. 11)
};

/// The candidates of every block and the threshold that filtered them (Figure 4: blue marks are
/// the candidates, yellow marks the kept ones).
struct TransitionSelection {
  std::vector<TransitionCandidate> candidates;  ///< at most one per block, blocks row-major
  int blocksPerSide = 0;                         ///< M = ceil(N / B): at most M² candidates
  double a = 0.0;                                ///< smallest candidate cost (NaN: no candidate)
  double b = 0.0;                                ///< largest candidate cost (NaN: no candidate)
  double epsilon = 0.0;                          ///< ε of eq. 11 (NaN: no candidate)
  /// Number of kept candidates (the transition edges, at most M²).
  int keptCount() const;
};

/// Whether entry (i, j) of C may become a candidate: i ≠ j; j is not the last node of its state
/// (the edge i → j + 1 needs j's successor); and, for i and j of one state, |i − j| > max(1,
/// minNodeGap) (§4.3 "we also filter the edges whose nodes are close"; |i − j| <= 1 would give a
/// duplicate of a temporal edge or a self loop). `state` and `offsets` from nodeStates() and
/// stateOffsets().
bool transitionEligible(int i, int j, const std::vector<int>& state, const std::vector<int>& offsets, int minNodeGap);

/// §4.3: cuts C into B×B blocks (node order of the matrix, blocks across state boundaries too),
/// takes the minimum eligible entry of each block as candidate, a and b as the smallest and
/// largest candidate cost, ε = (2a + b)/3 or the explicit ε, and keeps the candidates with
/// c < ε (eq. 11). Ties inside a block (always in a diagonal block, where c_ij = c_ji) go to the
/// entry with the larger row, i.e. below the diagonal: the backward jump i → j + 1 (j < i)
/// closes a loop, which lets a walk stay in a state, while the forward one only skips nodes.
/// Throws std::invalid_argument for invalid params or counts, or an explicit ε outside [a, b]
/// (the message gives a and b). No candidate at all (tiny graphs) is not an error: a, b and ε
/// are NaN and nothing is kept.
TransitionSelection selectTransitions(const CostMatrix& cost, const std::vector<int>& stateNodeCounts,
                                      const FlowGraphParams& params);

}  // namespace plume
