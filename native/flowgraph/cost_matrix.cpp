/// \file cost_matrix.cpp
/// The cost matrix C of eq. 9-10 (§4.3) with every group in memory, in tiles of node pairs
/// (cost_tiles.cpp holds the kernel, its blocking and its accumulation order).

#include "flowgraph/cost_matrix.h"

#include "core/parallel.h"
#include "flowgraph/cost_tiles.h"
#include "flowgraph/state_nodes.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace plume {

CostMatrix::CostMatrix(int size) {
  if (size < 0) throw std::invalid_argument("cost matrix size must be >= 0 (got " + std::to_string(size) + ")");
  mSize = size;
  mValues.assign(std::size_t(size) * std::size_t(size), 0.0);
}

CostMatrix CostMatrix::fromValues(int size, std::vector<double> values) {
  CostMatrix c(size);
  if (values.size() != c.mValues.size())
    throw std::invalid_argument("cost matrix: " + std::to_string(values.size()) + " values for " +
                                std::to_string(size) + " x " + std::to_string(size) + " nodes");
  c.mValues = std::move(values);
  for (int i = 0; i < size; ++i) {
    if (c(i, i) != 0.0)
      throw std::invalid_argument("cost matrix: c[" + std::to_string(i) + ", " + std::to_string(i) + "] = " +
                                  std::to_string(c(i, i)) + ", the diagonal must be 0 (eq. 9 of a node with itself)");
    for (int j = 0; j < size; ++j) {
      const double v = c(i, j);
      if (!(std::isfinite(v) && v >= 0.0))
        throw std::invalid_argument("cost matrix: c[" + std::to_string(i) + ", " + std::to_string(j) + "] = " +
                                    std::to_string(v) + ", costs must be finite and >= 0");
      if (v != c(j, i))
        throw std::invalid_argument("cost matrix: c[" + std::to_string(i) + ", " + std::to_string(j) + "] = " +
                                    std::to_string(v) + " but c[" + std::to_string(j) + ", " + std::to_string(i) +
                                    "] = " + std::to_string(c(j, i)) + ", it must be symmetric");
    }
  }
  return c;
}

CostMatrix computeCostMatrix(const std::vector<const PathlineGroup*>& groups, const FlowGraphParams& params,
                             CostMatrixProgress* progress) {
  params.validate();
  stateNodeCounts(groups);
  const int n = int(groups.size());
  const PathlineLayout layout = groups.front()->layout;
  std::vector<GroupArrays> arrays(groups.size());
  for (std::size_t g = 0; g < groups.size(); ++g) arrays[g] = groupArrays(*groups[g]);

  // Tiles (I, J), I <= J, of the upper triangle; each task owns its entries (and their mirrors).
  const int tiles = (n + kCostTile - 1) / kCostTile;
  std::vector<std::pair<int, int>> tasks;
  for (int ti = 0; ti < tiles; ++ti)
    for (int tj = ti; tj < tiles; ++tj) tasks.emplace_back(ti, tj);

  CostMatrix cost(n);
  ThreadLimit limit(params.threads);
  if (progress) progress->tiles = int(tasks.size());
  parallelFor(0, int(tasks.size()), [&](int t) {
    if (progress && progress->cancel.load(std::memory_order_relaxed)) return;
    const int i0 = tasks[std::size_t(t)].first * kCostTile, j0 = tasks[std::size_t(t)].second * kCostTile;
    costTile(&arrays[std::size_t(i0)], i0, std::min(kCostTile, n - i0), &arrays[std::size_t(j0)], j0,
             std::min(kCostTile, n - j0), layout, params, cost);
    if (progress) ++progress->tilesDone;
  });
  if (progress && progress->cancel.load()) return CostMatrix();
  return cost;
}

}  // namespace plume
