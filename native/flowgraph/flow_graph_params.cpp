/// \file flow_graph_params.cpp
/// FlowGraphParams checks and the "same order of magnitude" weights of eq. 9 (§4.3).

#include "flowgraph/flow_graph_params.h"

#include "core/format.h"
#include "core/parallel.h"
#include "flowgraph/state_nodes.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

/// Throws "<name> must be <what> (got v)" unless lo <= v <= hi and v is finite.
void requireWithin(const char* name, double v, double lo, double hi, const std::string& what) {
  if (!(std::isfinite(v) && v >= lo && v <= hi))
    throw std::invalid_argument(std::string(name) + " must be " + what + " (got " + formatNumber(v) + ")");
}

/// Σ over groups and elements of (x_g,e − x̄_e)², x̄ the mean over the groups, for one field
/// given as a flat float array of `count` values per group. Chunks of elements are summed in
/// index order (parallelSum), so the result does not depend on the thread count.
template <typename Field>
double squaredDeviations(const std::vector<const PathlineGroup*>& groups, std::size_t count, const Field& field) {
  constexpr std::size_t kChunk = 4096;
  const int chunks = int((count + kChunk - 1) / kChunk);
  const double inv = 1.0 / double(groups.size());
  return parallelSum(0, chunks, [&](int c) {
    const std::size_t e0 = std::size_t(c) * kChunk, n = std::min(kChunk, count - e0);
    std::vector<double> mean(n, 0.0);
    for (const PathlineGroup* g : groups) {
      const float* x = field(*g) + e0;
      for (std::size_t e = 0; e < n; ++e) mean[e] += x[e];
    }
    for (double& m : mean) m *= inv;
    double sum = 0.0;
    for (const PathlineGroup* g : groups) {
      const float* x = field(*g) + e0;
      for (std::size_t e = 0; e < n; ++e) sum += (x[e] - mean[e]) * (x[e] - mean[e]);
    }
    return sum;
  });
}

}  // namespace

void FlowGraphParams::validate() const {
  requireWithin("alpha", alpha, 0.0, HUGE_VAL, "a finite number >= 0 (weight of the density term of eq. 9)");
  requireWithin("beta", beta, 0.0, HUGE_VAL, "a finite number >= 0 (weight of the temperature term of eq. 9)");
  requireWithin("block_size", blockSize, 1, kMaxFlowGraphBlockSize,
                "in [1, " + std::to_string(kMaxFlowGraphBlockSize) + "] nodes");
  if (epsilonMode != EpsilonMode::TwoThirds && epsilonMode != EpsilonMode::Explicit)
    throw std::invalid_argument("epsilon_mode must be TWO_THIRDS or EXPLICIT");
  if (epsilonMode == EpsilonMode::Explicit)
    requireWithin("epsilon", epsilon, 0.0, HUGE_VAL,
                  "a finite cost >= 0 (it is checked against [a, b] once the candidates are known)");
  requireWithin("min_node_gap", minNodeGap, 0, kMaxFlowGraphNodeGap,
                "in [0, " + std::to_string(kMaxFlowGraphNodeGap) + "] node steps");
  requireWithin("threads", threads, 0, kMaxFlowGraphThreads,
                "in [0, " + std::to_string(kMaxFlowGraphThreads) + "] (0 = all cores)");
}

FlowWeights sameMagnitudeWeights(const std::vector<const PathlineGroup*>& groups, int threads) {
  stateNodeCounts(groups);  // one layout, arrays of its size
  requireWithin("threads", threads, 0, kMaxFlowGraphThreads,
                "in [0, " + std::to_string(kMaxFlowGraphThreads) + "] (0 = all cores)");
  ThreadLimit limit(threads);
  const std::size_t values = groups.front()->layout.values();
  // The common factor Δt_n / (|Ω| N) of eq. 9-10 and of the mean cancels in the ratios.
  const double u = squaredDeviations(groups, 3 * values,
                                     [](const PathlineGroup& g) { return &g.velocity.front().x; });
  const double r = squaredDeviations(groups, values, [](const PathlineGroup& g) { return g.density.data(); });
  const double t = squaredDeviations(groups, values, [](const PathlineGroup& g) { return g.temperature.data(); });
  const double reference = u > 0.0 ? u : 1.0;
  auto ratio = [&](double v) {
    const double q = reference / v;
    return v > 0.0 && std::isfinite(q) ? q : 1.0;
  };
  FlowWeights w;
  w.alpha = ratio(r);
  w.beta = ratio(t);
  return w;
}

}  // namespace plume
