#pragma once
/// \file magnitude_weights.h
/// The "same order of magnitude" weights α, β of eq. 9 ([Graph Fire Synthesis] §4.3), from
/// groups in memory or streamed from the states' pathline files.

#include "flowgraph/node_files.h"
#include "flowgraph/pathline_group.h"

#include <vector>

namespace plume {

/// The weights α (density) and β (temperature) of eq. 9.
struct FlowWeights {
  double alpha = 1.0;
  double beta = 1.0;
};

/// α and β of eq. 9 that bring the three terms to the same order of magnitude (§4.3: "α and β
/// are set such that the differences of velocity, density and temperature are in the same order
/// of magnitude"): α = mean ‖U_i − U_j‖² / mean ‖R_i − R_j‖² and β = mean ‖U_i − U_j‖² /
/// mean ‖T_i − T_j‖², means over all pairs of groups and over the lifetime. They are computed
/// without the pairs through mean_ij ‖X_i − X_j‖² = 2 mean_i ‖X_i − X̄‖² (X̄: the mean group),
/// i.e. as ratios of variances. Differences rather than the fields' own norms mean ‖U‖²/‖R‖²:
/// eq. 9 only ever sees differences, and a constant offset (an ambient temperature of 300 K)
/// would inflate ‖T‖² and silence the temperature term. A field that never varies gets weight 1
/// (its term is 0 whatever the weight); if velocity never varies, the reference is 1 instead of
/// its variance. Throws std::invalid_argument on groups that do not share one layout, or on
/// threads outside [0, kMaxFlowGraphThreads] (0 = all cores). The same bits at any thread count.
FlowWeights sameMagnitudeWeights(const std::vector<const PathlineGroup*>& groups, int threads = 0);

/// The same weights, bit for bit, from the states' pathline files: two passes over the nodes
/// (the mean group X̄, then the squared deviations from it), kWeightBatch groups in memory at a
/// time. Also throws what NodeFiles::read() throws.
FlowWeights sameMagnitudeWeights(const NodeFiles& nodes, int threads = 0);

/// Groups read per batch by the streamed sameMagnitudeWeights().
constexpr int kWeightBatch = 32;


}  // namespace plume
