#pragma once
/// \file cost_tiles.h
/// One tile of node pairs of the cost matrix of eq. 9-10 ([Graph Fire Synthesis] §4.3): the
/// kernel shared by the in-memory build (cost_matrix.cpp, every group at hand) and the streamed
/// one (cost_matrix_stream.cpp, the groups of two blocks at a time). An entry c_ij depends on
/// groups i and j only and is summed in one fixed order whatever tile holds it, so both builds
/// give the same bits.

#include "flowgraph/cost_matrix.h"
#include "flowgraph/flow_graph_params.h"
#include "flowgraph/pathline_group.h"

namespace plume {

/// Side of a tile: kCostTile × kCostTile node pairs per task.
constexpr int kCostTile = 32;

/// One group's sample arrays as flat floats (velocity: 3 per sample).
struct GroupArrays {
  const float* velocity;
  const float* density;
  const float* temperature;
};

/// The arrays of `g` (which must outlive their use).
GroupArrays groupArrays(const PathlineGroup& g);

/// Sets c_ij and c_ji of eq. 9-10 for the nodes i = i0 + r (r < nRows, arrays rows[r]) and
/// j = j0 + q (q < nCols, arrays cols[q]), nRows and nCols <= kCostTile, j0 >= i0; on a diagonal
/// tile (i0 == j0, rows == cols) only the pairs j > i. Uses params.alpha and beta.
void costTile(const GroupArrays* rows, int i0, int nRows, const GroupArrays* cols, int j0, int nCols,
              const PathlineLayout& layout, const FlowGraphParams& params, CostMatrix& cost);

/// Tiles of the upper triangle of an N×N matrix: T(T+1)/2 for T = ceil(N / kCostTile).
inline int costTileCount(int nodes) {
  const int t = (nodes + kCostTile - 1) / kCostTile;
  return t * (t + 1) / 2;
}

}  // namespace plume
