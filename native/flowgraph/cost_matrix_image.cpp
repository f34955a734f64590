/// \file cost_matrix_image.cpp
/// Figure 4 of §4.3: the cost matrix in grey with the candidate and kept transitions.

#include "flowgraph/cost_matrix_image.h"

#include "flowgraph/state_nodes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

using Rgb = std::array<std::uint8_t, 3>;
constexpr Rgb kFiltered = {40, 90, 255};   // blue: candidate, cost >= ε
constexpr Rgb kKept = {255, 220, 0};       // yellow: transition edge
constexpr Rgb kStateLine = {200, 30, 30};  // red: state boundary

/// The p-quantile (0..1) of the off-diagonal costs (nearest rank).
double quantile(std::vector<double>& values, double p) {
  const std::size_t k = std::size_t(p * double(values.size() - 1) + 0.5);
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
  return values[k];
}

}  // namespace

RgbImage costMatrixImage(const CostMatrix& cost, const TransitionSelection& selection,
                         const std::vector<int>& stateNodeCounts, int size) {
  if (size < 1 || size > kMaxCostImageSize)
    throw std::invalid_argument("size must be in [1, " + std::to_string(kMaxCostImageSize) + "] pixels (got " +
                                std::to_string(size) + ")");
  const std::vector<int> offsets = stateOffsets(stateNodeCounts);
  const int n = cost.size();
  if (offsets.back() != n)
    throw std::invalid_argument("state_node_counts add up to " + std::to_string(offsets.back()) +
                                " nodes, the cost matrix has " + std::to_string(n));
  RgbImage img;
  img.width = img.height = size;
  img.pixels.assign(std::size_t(size) * std::size_t(size) * 3, 0);
  auto put = [&](int x, int y, const Rgb& c) {
    if (x < 0 || y < 0 || x >= size || y >= size) return;
    std::copy(c.begin(), c.end(), img.pixels.begin() + std::ptrdiff_t((std::size_t(y) * std::size_t(size) + std::size_t(x)) * 3));
  };

  // Grey background: darker = lower cost, between robust bounds.
  std::vector<double> off;
  off.reserve(std::size_t(n) * std::size_t(n));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if (i != j) off.push_back(cost(i, j));
  double lo = 0.0, hi = 0.0;
  if (!off.empty()) {
    lo = quantile(off, 0.02);
    hi = quantile(off, 0.98);
  }
  auto node = [&](int pixel) { return int(std::int64_t(pixel) * n / size); };
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double c = cost(node(y), node(x));
      const double g = hi > lo ? std::clamp((c - lo) / (hi - lo), 0.0, 1.0) : (off.empty() ? 0.0 : 0.5);
      const auto v = std::uint8_t(std::lround(255.0 * g));
      put(x, y, {v, v, v});
    }

  // State boundaries, then the marks over them (kept ones last, so they stay visible).
  for (std::size_t s = 1; s + 1 < offsets.size(); ++s) {
    const int p = int(std::int64_t(offsets[s]) * size / n);
    for (int t = 0; t < size; ++t) {
      put(p, t, kStateLine);
      put(t, p, kStateLine);
    }
  }
  const int r = std::max(1, size / 256);
  for (bool kept : {false, true})
    for (const TransitionCandidate& c : selection.candidates) {
      if (c.kept != kept) continue;
      const int cx = int((double(c.col) + 0.5) * size / n), cy = int((double(c.row) + 0.5) * size / n);
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) put(cx + dx, cy + dy, kept ? kKept : kFiltered);
    }
  return img;
}

}  // namespace plume
