/// \file transitions.cpp
/// Block-local minima of the cost matrix and the ε filter of eq. 11 (§4.3).

#include "flowgraph/transitions.h"

#include "flowgraph/state_nodes.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace plume {

int TransitionSelection::keptCount() const {
  return int(std::count_if(candidates.begin(), candidates.end(), [](const TransitionCandidate& c) { return c.kept; }));
}

bool transitionEligible(int i, int j, const std::vector<int>& state, const std::vector<int>& offsets, int minNodeGap) {
  if (i == j) return false;
  const int sj = state[std::size_t(j)];
  if (j + 1 == offsets[std::size_t(sj) + 1]) return false;  // j is the last node of its state
  return state[std::size_t(i)] != sj || std::abs(i - j) > std::max(1, minNodeGap);
}

TransitionSelection selectTransitions(const CostMatrix& cost, const std::vector<int>& stateNodeCounts,
                                      const FlowGraphParams& params) {
  params.validate();
  const std::vector<int> offsets = stateOffsets(stateNodeCounts);
  const int n = cost.size();
  if (offsets.back() != n)
    throw std::invalid_argument("state_node_counts add up to " + std::to_string(offsets.back()) +
                                " nodes, the cost matrix has " + std::to_string(n));
  const std::vector<int> state = nodeStates(offsets);
  const int B = params.blockSize;
  TransitionSelection sel;
  sel.blocksPerSide = (n + B - 1) / B;
  for (int bi = 0; bi < sel.blocksPerSide; ++bi)
    for (int bj = 0; bj < sel.blocksPerSide; ++bj) {
      TransitionCandidate best;
      best.row = -1;
      best.cost = std::numeric_limits<double>::infinity();
      for (int i = bi * B; i < std::min(n, (bi + 1) * B); ++i)
        for (int j = bj * B; j < std::min(n, (bj + 1) * B); ++j) {
          if (!transitionEligible(i, j, state, offsets, params.minNodeGap)) continue;
          const double c = cost(i, j);
          // Rows ascend, so ">=" on a tie moves the choice to the larger row (see header).
          if (c < best.cost || (c == best.cost && best.row >= 0 && i > best.row)) best = {i, j, c, false};
        }
      if (best.row >= 0) sel.candidates.push_back(best);
    }

  const double nan = std::numeric_limits<double>::quiet_NaN();
  sel.a = sel.b = sel.epsilon = nan;
  if (sel.candidates.empty()) return sel;
  auto [lo, hi] = std::minmax_element(sel.candidates.begin(), sel.candidates.end(),
                                      [](const TransitionCandidate& x, const TransitionCandidate& y) {
                                        return x.cost < y.cost;
                                      });
  sel.a = lo->cost;
  sel.b = hi->cost;
  if (params.epsilonMode == EpsilonMode::TwoThirds) {
    sel.epsilon = (2.0 * sel.a + sel.b) / 3.0;
  } else {
    if (!(params.epsilon >= sel.a && params.epsilon <= sel.b)) {
      std::ostringstream m;
      m << std::setprecision(10) << "epsilon must be in [a, b] = [" << sel.a << ", " << sel.b
        << "], the smallest and largest candidate transition costs of this cost matrix (got " << params.epsilon
        << ")";
      throw std::invalid_argument(m.str());
    }
    sel.epsilon = params.epsilon;
  }
  for (TransitionCandidate& c : sel.candidates) c.kept = c.cost < sel.epsilon;
  return sel;
}

}  // namespace plume
