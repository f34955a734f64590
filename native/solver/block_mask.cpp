#include "solver/block_mask.h"

#include <algorithm>
#include <cstring>

namespace plume {

void BlockMask::build(const ScalarGrid& field, float background, int dilation) {
  const glm::ivec3 n = field.size();
  mBlocks = (n + kBlock - 1) / kBlock;
  const std::size_t count = std::size_t(mBlocks.x) * mBlocks.y * mBlocks.z;
  mRaw.assign(count, 0);
  mActive.assign(count, 0);
  auto at = [&](int bi, int bj, int bk) {
    return std::size_t(bi) + std::size_t(mBlocks.x) * (std::size_t(bj) + std::size_t(mBlocks.y) * bk);
  };
  // Each block z-layer is written by one task only.
  parallelFor(0, mBlocks.z, [&](int bk) {
    for (int k = bk * kBlock; k < std::min(n.z, (bk + 1) * kBlock); ++k)
      for (int j = 0; j < n.y; ++j) {
        const float* row = &field.values()[field.index(0, j, k)];
        for (int i = 0; i < n.x; ++i)
          if (row[i] != background) mRaw[at(i / kBlock, j / kBlock, bk)] = 1;
      }
  });
  parallelFor(0, mBlocks.z, [&](int bk) {
    for (int bj = 0; bj < mBlocks.y; ++bj)
      for (int bi = 0; bi < mBlocks.x; ++bi) {
        std::uint8_t any = 0;
        for (int dk = -dilation; dk <= dilation && !any; ++dk)
          for (int dj = -dilation; dj <= dilation && !any; ++dj)
            for (int di = -dilation; di <= dilation && !any; ++di) {
              const int a = bi + di, b = bj + dj, c = bk + dk;
              if (a < 0 || b < 0 || c < 0 || a >= mBlocks.x || b >= mBlocks.y || c >= mBlocks.z)
                continue;
              any = mRaw[at(a, b, c)];
            }
        mActive[at(bi, bj, bk)] = any;
      }
  });
}

void BlockMask::merge(const BlockMask& other) {
  if (mActive.size() != other.mActive.size()) {
    *this = other;
    return;
  }
  for (std::size_t n = 0; n < mActive.size(); ++n) mActive[n] |= other.mActive[n];
}

void BlockMask::setAll(glm::ivec3 size) {
  mBlocks = (size + kBlock - 1) / kBlock;
  mActive.assign(std::size_t(mBlocks.x) * mBlocks.y * mBlocks.z, 1);
}

void CleanStencils::build(const ScalarGrid& field, float background, const BlockMask* mask) {
  const glm::ivec3 n = field.size();
  constexpr int B = BlockMask::kBlock;
  mDirty.resize(field.count());
  mScratch.resize(field.count());
  std::uint32_t bg;
  std::memcpy(&bg, &background, sizeof bg);
  const auto* bits = reinterpret_cast<const std::uint32_t*>(field.data());
  const std::size_t sy = std::size_t(n.x), sz = std::size_t(n.x) * std::size_t(n.y);
  // With a mask, the field is its background outside the active blocks (the mask covers the
  // smoke, and the passes write the background there), so cells further than a block from an
  // active one are clean: only the active blocks are tested, and only they and their neighbours
  // (mNear) dilated; everything else stays 0 from the fill.
  if (mask) {
    const glm::ivec3 nb = mask->blocks();
    mNear.assign(std::size_t(nb.x) * std::size_t(nb.y) * std::size_t(nb.z), 0);
    for (int bk = 0; bk < nb.z; ++bk)
      for (int bj = 0; bj < nb.y; ++bj)
        for (int bi = 0; bi < nb.x; ++bi) {
          std::uint8_t any = 0;
          for (int dk = -1; dk <= 1; ++dk)
            for (int dj = -1; dj <= 1; ++dj)
              for (int di = -1; di <= 1; ++di) {
                const int a = bi + di, b = bj + dj, c = bk + dk;
                if (a >= 0 && b >= 0 && c >= 0 && a < nb.x && b < nb.y && c < nb.z)
                  any |= mask->active(a, b, c) ? 1 : 0;
              }
          mNear[std::size_t(bi) + std::size_t(nb.x) * (std::size_t(bj) + std::size_t(nb.y) * bk)] = any;
        }
    parallelFor(0, n.z, [&](int k) {
      std::fill_n(mDirty.data() + std::size_t(k) * sz, sz, std::uint8_t(0));
      std::fill_n(mScratch.data() + std::size_t(k) * sz, sz, std::uint8_t(0));
    });
  }
  // fn(i0, i1) for the x-runs of row (j, k) in active blocks (near = false) or in active blocks
  // and their neighbours (near = true); the whole row without a mask.
  auto segments = [&](int j, int k, bool near, const auto& fn) {
    if (!mask) return fn(0, n.x);
    const glm::ivec3 nb = mask->blocks();
    for (int bi = 0; bi < nb.x; ++bi) {
      const bool on = near ? mNear[std::size_t(bi) + std::size_t(nb.x) * (std::size_t(j / B) +
                                                                      std::size_t(nb.y) * (k / B))] != 0
                           : mask->active(bi, j / B, k / B);
      if (on) fn(bi * B, std::min(n.x, bi * B + B));
    }
  };
  // Separable: each cell's own test, then along x (cells i-1 .. i+2 of a row), y, z; each pass
  // reads one buffer and writes the other, so that the z-slices run in parallel.
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j) {
      const std::size_t r = std::size_t(k) * sz + std::size_t(j) * sy;
      segments(j, k, false, [&](int i0, int i1) {
        for (int i = i0; i < i1; ++i) mDirty[r + i] = bits[r + i] != bg ? 1 : 0;
      });
    }
  });
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j) {
      const std::uint8_t* in = mDirty.data() + std::size_t(k) * sz + std::size_t(j) * sy;
      std::uint8_t* out = mScratch.data() + std::size_t(k) * sz + std::size_t(j) * sy;
      auto at = [&](int i) -> std::uint8_t { return i >= 0 && i < n.x ? in[i] : 0; };
      segments(j, k, true, [&](int i0, int i1) {
        // Cells with i-1 .. i+2 inside the row (1 .. n.x-3) without bounds tests.
        const int lo = std::max(i0, 1), hi = std::min(i1, n.x - 2);
        for (int i = lo; i < hi; ++i) out[i] = in[i - 1] | in[i] | in[i + 1] | in[i + 2];
        for (int i = i0; i < i1; ++i)
          if (i < lo || i >= hi) out[i] = at(i - 1) | at(i) | at(i + 1) | at(i + 2);
      });
    }
  });
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j) {
      std::uint8_t* out = mDirty.data() + std::size_t(k) * sz + std::size_t(j) * sy;
      const int b0 = std::max(j - 1, 0), b1 = std::min(j + 2, n.y - 1);
      segments(j, k, true, [&](int i0, int i1) {
        for (int i = i0; i < i1; ++i) {
          std::uint8_t any = 0;
          for (int b = b0; b <= b1; ++b) any |= mScratch[std::size_t(k) * sz + std::size_t(b) * sy + std::size_t(i)];
          out[i] = any;
        }
      });
    }
  });
  parallelFor(0, n.z, [&](int k) {
    const int c0 = std::max(k - 1, 0), c1 = std::min(k + 2, n.z - 1);
    for (int j = 0; j < n.y; ++j) {
      std::uint8_t* out = mScratch.data() + std::size_t(k) * sz + std::size_t(j) * sy;
      segments(j, k, true, [&](int i0, int i1) {
        for (int i = i0; i < i1; ++i) {
          std::uint8_t any = 0;
          for (int c = c0; c <= c1; ++c) any |= mDirty[std::size_t(c) * sz + std::size_t(j) * sy + std::size_t(i)];
          out[i] = any;
        }
      });
    }
  });
  std::swap(mDirty, mScratch);
}

float BlockMask::fill() const {
  if (mActive.empty()) return 0.f;
  std::size_t on = 0;
  for (std::uint8_t a : mActive) on += a;
  return float(on) / float(mActive.size());
}

}  // namespace plume
