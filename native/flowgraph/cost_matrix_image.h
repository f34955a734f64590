#pragma once
/// \file cost_matrix_image.h
/// A picture of the cost matrix like Figure 4 of [Graph Fire Synthesis] (§4.3): grey-scale
/// costs (darker = lower), blue marks on the filtered candidates, yellow marks on the kept
/// transitions, thin red lines between states.

#include "flowgraph/cost_matrix.h"
#include "flowgraph/transitions.h"

#include <cstdint>
#include <vector>

namespace plume {

/// An 8-bit RGB picture, row-major, top row first, 3 bytes per pixel.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;
};

/// Largest side of costMatrixImage().
constexpr int kMaxCostImageSize = 8192;

/// Figure 4 for C: a size × size picture in which pixel (x, y) shows c_ij of the node pair
/// (i, j) = (y N / size, x N / size) (row i from the top), grey = (c − lo)/(hi − lo) with lo, hi
/// the 2nd and 98th percentiles of the off-diagonal costs (robust to a few outliers), clamped.
/// Candidates that ε filtered out are blue squares, kept ones yellow (size/256 pixels around the
/// entry, at least 1), drawn over red one-pixel lines at the state boundaries. Throws
/// std::invalid_argument for size outside [1, kMaxCostImageSize] or node counts that do not
/// add up to N.
RgbImage costMatrixImage(const CostMatrix& cost, const TransitionSelection& selection,
                         const std::vector<int>& stateNodeCounts, int size);

}  // namespace plume
