#pragma once
/// \file block_mask.h
/// Sparse work for advection (skip advection in blocks with no smoke): blocks of
/// 8³ samples that may hold something other than a field's background value, and the loop over
/// the x-runs of a grid that lie in them.

#include "core/grid3.h"
#include "core/parallel.h"

#include <cstdint>
#include <vector>

namespace plume {

/// Blocks of 8³ samples that may hold something other than a field's background value after
/// advection: blocks holding such a value, dilated by two blocks (16 cells) or as many as the
/// step's reach asks for.
class BlockMask {
 public:
  static constexpr int kBlock = 8;
  static constexpr int kDilation = 2;  ///< blocks; covers 2 × (trace + stencil) of BFECC

  /// Marks the blocks of `field` with a value != background, then dilates by `dilation` blocks.
  void build(const ScalarGrid& field, float background, int dilation = kDilation);
  /// Union with another mask of the same grid.
  void merge(const BlockMask& other);
  /// Marks everything active.
  void setAll(glm::ivec3 size);
  bool active(int bi, int bj, int bk) const {
    return mActive[std::size_t(bi) + std::size_t(mBlocks.x) * (std::size_t(bj) + std::size_t(mBlocks.y) * std::size_t(bk))] != 0;
  }
  glm::ivec3 blocks() const { return mBlocks; }
  /// Share of active blocks, in [0, 1].
  float fill() const;

 private:
  glm::ivec3 mBlocks{0};
  std::vector<std::uint8_t> mActive, mRaw;
};

/// Cells whose monotonic cubic stencil (i-1 .. i+2 on each axis, clamped into the grid) holds
/// the field's background value only, bit for bit: the cubic (and trilinear) sample of a point
/// in such a cell is that value exactly, so the cubic advection passes skip the sampling of a
/// run whose points all fall in such cells. In a rising plume most cells are such cells, even in
/// the active blocks (dilated by 16 cells around the smoke: 80–93% of their cells at 64³).
class CleanStencils {
 public:
  /// Marks the cells of `field`, which must be its background outside the active blocks of
  /// `mask` (nullptr: no mask); allocates on the first call for a grid of this size only.
  void build(const ScalarGrid& field, float background, const BlockMask* mask);
  /// Per cell (linear index): 0 when its stencil is all background.
  const std::uint8_t* dirty() const { return mDirty.data(); }

 private:
  std::vector<std::uint8_t> mDirty, mScratch;
  std::vector<std::uint8_t> mNear;  ///< per block: active or next to an active block
};

/// Calls run(setup(j, k), i0, i1, j, k) for the x-runs [i0, i1) of each row of a grid of n
/// samples that lie in active blocks of `mask` (nullptr: all), and idle(i0, i1, j, k) for the
/// others; setup(j, k) runs once per row, for what the runs of a row share. Runs are at most
/// BlockMask::kBlock long and start at multiples of it; z-slices run in parallel.
template <typename Setup, typename Run, typename Idle>
void forEachRunOfRows(glm::ivec3 n, const BlockMask* mask, const Setup& setup, const Run& run,
                      const Idle& idle) {
  constexpr int B = BlockMask::kBlock;
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j) {
      const auto row = setup(j, k);
      for (int i0 = 0; i0 < n.x; i0 += B) {
        const int i1 = std::min(n.x, i0 + B);
        if (!mask || mask->active(i0 / B, j / B, k / B)) run(row, i0, i1, j, k);
        else idle(i0, i1, j, k);
      }
    }
  });
}

/// forEachRunOfRows() without a row setup: run(i0, i1, j, k).
template <typename Run, typename Idle>
void forEachRun(glm::ivec3 n, const BlockMask* mask, const Run& run, const Idle& idle) {
  forEachRunOfRows(
      n, mask, [](int, int) { return 0; },
      [&](int, int i0, int i1, int j, int k) { run(i0, i1, j, k); }, idle);
}

}  // namespace plume
