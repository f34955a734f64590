#pragma once
/// \file active_box.h
/// The box of the adaptive domain (adaptive_domain.h): which cells hold smoke, heat or fuel, the
/// margin and block rounding around them, and the copies of a grid between the full domain and
/// the box. Pure functions of the grids; each result is the same at any thread count (the box is
/// a min/max reduction, the copies are element-wise).

#include "core/grid3.h"

#include <glm/glm.hpp>

namespace plume {

/// Cells [lo, hi) of the full domain; empty when some hi <= lo.
struct ActiveBox {
  glm::ivec3 lo{0};
  glm::ivec3 hi{0};

  bool empty() const { return glm::any(glm::lessThanEqual(hi, lo)); }
  glm::ivec3 size() const { return hi - lo; }
  bool operator==(const ActiveBox& o) const { return lo == o.lo && hi == o.hi; }
  bool operator!=(const ActiveBox& o) const { return !(*this == o); }
  /// The smallest box holding both (an empty one adds nothing).
  ActiveBox united(const ActiveBox& o) const;
  /// The box grown by the cells [lo, hi] (inclusive), clamped to `resolution`.
  ActiveBox withCells(glm::ivec3 lo, glm::ivec3 hi, glm::ivec3 resolution) const;
};

/// Side of the blocks the box is rounded to, so that it changes only when the smoke crosses a
/// block, not at every cell it grows by (each change rebuilds the box's solver).
constexpr int kActiveBoxBlock = 8;

/// Box of the cells of `grid` (placed at `offset` in the full domain) whose |value - background|
/// is above `threshold`, united with `box`.
ActiveBox uniteActive(const ActiveBox& box, const ScalarGrid& grid, float background,
                      float threshold, glm::ivec3 offset);

/// `box` grown by `margin` cells on every side, rounded outwards to kActiveBoxBlock and clamped
/// to the domain [0, resolution).
ActiveBox padBox(const ActiveBox& box, int margin, glm::ivec3 resolution);

/// box(i, j, k) = full(offset + (i, j, k)) over the box grid's size (cells or faces alike).
template <typename T>
void copyToBox(const Grid3<T>& full, Grid3<T>& box, glm::ivec3 offset);
/// full(offset + (i, j, k)) = box(i, j, k) over the box grid's size.
template <typename T>
void copyFromBox(const Grid3<T>& box, Grid3<T>& full, glm::ivec3 offset);

/// Sets to `value` the samples of `full` in the region of size `oldSize` at `oldOffset` that lie
/// outside the region of size `newSize` at `newOffset`: the air a shrinking box leaves behind.
/// `ambient`, when given, holds the value per sample instead (a wind field on the faces).
void fillLeftBehind(ScalarGrid& full, glm::ivec3 oldOffset, glm::ivec3 oldSize,
                    glm::ivec3 newOffset, glm::ivec3 newSize, float value,
                    const ScalarGrid* ambient = nullptr);

}  // namespace plume
