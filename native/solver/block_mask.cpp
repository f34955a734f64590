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

void CleanStencils::build(const ScalarGrid& field, float background) {
  const glm::ivec3 n = field.size();
  mDirty.resize(field.count());
  mScratch.resize(field.count());
  std::uint32_t bg;
  std::memcpy(&bg, &background, sizeof bg);
  const auto* bits = reinterpret_cast<const std::uint32_t*>(field.data());
  const std::size_t sy = std::size_t(n.x), sz = std::size_t(n.x) * std::size_t(n.y);
  // Separable: along x (cells i-1 .. i+2 of a row), then y, then z; each pass reads one buffer
  // and writes the other, so that the z-slices run in parallel.
  // mDirty holds each cell's own test until the y pass overwrites it.
  parallelFor(0, n.z, [&](int k) {
    const std::size_t s = std::size_t(k) * sz;
    for (std::size_t c = 0; c < sz; ++c) mDirty[s + c] = bits[s + c] != bg ? 1 : 0;
    for (int j = 0; j < n.y; ++j) {
      const std::uint8_t* in = mDirty.data() + s + std::size_t(j) * sy;
      std::uint8_t* out = mScratch.data() + s + std::size_t(j) * sy;
      auto at = [&](int i) -> std::uint8_t { return i >= 0 && i < n.x ? in[i] : 0; };
      const int inner = n.x - 2;  // cells i with i-1 .. i+2 inside the row: 1 .. n.x-3
      for (int i = 1; i < inner; ++i) out[i] = in[i - 1] | in[i] | in[i + 1] | in[i + 2];
      for (int i : {0, inner, inner + 1})
        if (i >= 0 && i < n.x) out[i] = at(i - 1) | at(i) | at(i + 1) | at(i + 2);
    }
  });
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j) {
      std::uint8_t* out = mDirty.data() + std::size_t(k) * sz + std::size_t(j) * sy;
      const int b0 = std::max(j - 1, 0), b1 = std::min(j + 2, n.y - 1);
      const std::uint8_t* first = mScratch.data() + std::size_t(k) * sz + std::size_t(b0) * sy;
      std::copy(first, first + sy, out);
      for (int b = b0 + 1; b <= b1; ++b) {
        const std::uint8_t* in = mScratch.data() + std::size_t(k) * sz + std::size_t(b) * sy;
        for (std::size_t i = 0; i < sy; ++i) out[i] |= in[i];
      }
    }
  });
  parallelFor(0, n.z, [&](int k) {
    std::uint8_t* out = mScratch.data() + std::size_t(k) * sz;
    const int c0 = std::max(k - 1, 0), c1 = std::min(k + 2, n.z - 1);
    const std::uint8_t* first = mDirty.data() + std::size_t(c0) * sz;
    std::copy(first, first + sz, out);
    for (int c = c0 + 1; c <= c1; ++c) {
      const std::uint8_t* in = mDirty.data() + std::size_t(c) * sz;
      for (std::size_t i = 0; i < sz; ++i) out[i] |= in[i];
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
