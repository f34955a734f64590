#pragma once
/// \file flow_graph_params.h
/// Settings of the flow graph ([Graph Fire Synthesis] §4.3): the weights α, β of the
/// transition cost (eq. 9), the block size B of the candidate search, the threshold ε of
/// eq. 11 and the temporal gap below which two nodes of one state are never connected.

#include "flowgraph/pathline_group.h"

#include <vector>

namespace plume {

/// How ε of eq. 11 is chosen from a = min and b = max of the candidate costs (§4.3).
enum class EpsilonMode {
  TwoThirds,  ///< ε = (2a + b) / 3, the paper's setting
  Explicit,   ///< ε = FlowGraphParams::epsilon, which must lie in [a, b]
};

/// Limits of the accepted settings (validate() names them in its messages).
constexpr int kMaxFlowGraphBlockSize = 1 << 20;
constexpr int kMaxFlowGraphNodeGap = 1 << 20;
constexpr int kMaxFlowGraphThreads = 1024;

/// Every setting of the graph build (§4.3).
struct FlowGraphParams {
  /// α of eq. 9: weight of the soot-density difference ‖R_i − R_j‖². The default 1 suits
  /// Plume's default units (velocity in m/s, soot and temperature of order 1); for other
  /// data, sameMagnitudeWeights() (magnitude_weights.h) gives the paper's "same order of magnitude" weights.
  double alpha = 1.0;
  /// β of eq. 9: weight of the temperature difference ‖T_i − T_j‖² (default 1, see alpha).
  double beta = 1.0;
  /// B: the cost matrix is cut into B×B blocks, one candidate transition per block (§4.3,
  /// "we use B = 32"). B = 1 makes every eligible pair a candidate.
  int blockSize = 32;
  /// How ε is chosen (eq. 11); EpsilonMode::TwoThirds is the paper's (2a + b) / 3.
  EpsilonMode epsilonMode = EpsilonMode::TwoThirds;
  /// ε for EpsilonMode::Explicit; checked against [a, b] once the candidates are known.
  double epsilon = 0.0;
  /// Pairs of nodes of one state at most this many node steps apart are no candidates (§4.3:
  /// "we also filter the edges whose nodes are close"). Successive groups sample nearly the same
  /// flow, so without the gap the minimum of every diagonal block sits next to the diagonal and
  /// the transition only skips or repeats one or two steps: a loop of 2-3 nodes, a visible
  /// stutter. 8 = B/4 at the paper's B = 32: a candidate in a diagonal block then joins nodes at
  /// least 9 steps apart (a loop of >= 9 nodes), and 54% of the block stays eligible. Lower it
  /// with B (B/4 keeps the same proportions); |i − j| <= 1 is always dropped
  /// (the diagonal and the temporal pairs, whose transitions would duplicate a temporal edge or
  /// loop on one node).
  int minNodeGap = 8;
  /// Worker threads of the cost matrix; 0 = all cores. Results do not depend on it.
  int threads = 0;

  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
};

}  // namespace plume
