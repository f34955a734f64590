/// \file flow_graph_params.cpp
/// FlowGraphParams checks (§4.3).

#include "flowgraph/flow_graph_params.h"

#include "core/format.h"

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

}  // namespace plume
