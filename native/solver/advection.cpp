#include "solver/advection.h"

#include "core/parallel.h"

namespace plume {
namespace {

/// Calls run(i0, i1, j, k) for the x-runs of each row that lie in active blocks, and
/// idle(i0, i1, j, k) for the others.
template <typename Run, typename Idle>
void forEachRun(glm::ivec3 n, const BlockMask* mask, const Run& run, const Idle& idle) {
  constexpr int B = BlockMask::kBlock;
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j)
      for (int i0 = 0; i0 < n.x; i0 += B) {
        const int i1 = std::min(n.x, i0 + B);
        if (!mask || mask->active(i0 / B, j / B, k / B)) run(i0, i1, j, k);
        else idle(i0, i1, j, k);
      }
  });
}

/// One semi-Lagrangian pass over traced positions: dst(x) = src(trace(x)). With `clampTo`, the
/// result is limited to the range of *clampTo around the traced point (BFECC's limiter).
void pass(const ScalarGrid& src, ScalarGrid& dst, const std::vector<glm::vec3>& traced,
          Interpolation interpolation, const ScalarGrid* clampTo, const BlockMask* mask,
          float background) {
  forEachRun(
      src.size(), mask,
      [&](int i0, int i1, int j, int k) {
        std::size_t c = src.index(i0, j, k);
        for (int i = i0; i < i1; ++i, ++c) {
          const glm::vec3 q = traced[c];
          float value = sample(src, q, interpolation);
          if (clampTo) {
            float lo, hi;
            sampleRange(*clampTo, q, lo, hi);
            value = value < lo ? lo : (value > hi ? hi : value);
          }
          dst[c] = value;
        }
      },
      [&](int i0, int i1, int j, int k) {
        std::size_t c = src.index(i0, j, k);
        for (int i = i0; i < i1; ++i, ++c) dst[c] = background;
      });
}

}  // namespace

glm::vec3 traceBack(const MacGrid3& velocity, glm::vec3 p, float cells) {
  const glm::vec3 v1 = sampleVelocity(velocity, p);
  const glm::vec3 mid = p - 0.5f * cells * v1;
  const glm::vec3 v2 = sampleVelocity(velocity, mid);
  return p - cells * v2;
}

// ---------------------------------------------------------------------------------------------

void BlockMask::build(const ScalarGrid& field, float background) {
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
        for (int dk = -kDilation; dk <= kDilation && !any; ++dk)
          for (int dj = -kDilation; dj <= kDilation && !any; ++dj)
            for (int di = -kDilation; di <= kDilation && !any; ++di) {
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

float BlockMask::fill() const {
  if (mActive.empty()) return 0.f;
  std::size_t on = 0;
  for (std::uint8_t a : mActive) on += a;
  return float(on) / float(mActive.size());
}

// ---------------------------------------------------------------------------------------------

void Advector::reserve(std::size_t count) {
  mForward.reserve(count);
  mBackward.reserve(count);
  mBack.reserve(count);
  mFore.reserve(count);
}

void Advector::trace(const MacGrid3& velocity, glm::ivec3 size, glm::vec3 offset, float dt,
                     float cellSize, Advection scheme, const BlockMask* mask) {
  mScheme = scheme;
  const std::size_t count = std::size_t(size.x) * size.y * size.z;
  mBack.resize(count);
  if (scheme == Advection::Bfecc) mFore.resize(count);
  const float cells = dt / cellSize;
  const bool both = scheme == Advection::Bfecc;
  forEachRun(
      size, mask,
      [&](int i0, int i1, int j, int k) {
        std::size_t c = std::size_t(i0) + std::size_t(size.x) * (std::size_t(j) + std::size_t(size.y) * k);
        for (int i = i0; i < i1; ++i, ++c) {
          const glm::vec3 p = glm::vec3(i, j, k) + offset;
          // Positions are stored in the grid's own index space (cell coordinates - offset).
          mBack[c] = traceBack(velocity, p, cells) - offset;
          if (both) mFore[c] = traceBack(velocity, p, -cells) - offset;
        }
      },
      [](int, int, int, int) {});
}

void Advector::advect(const ScalarGrid& src, ScalarGrid& dst, Interpolation interpolation,
                      const BlockMask* mask, float background) {
  dst.reshape(src.size());
  if (mScheme == Advection::SemiLagrangian) {
    pass(src, dst, mBack, interpolation, nullptr, mask, background);
    return;
  }
  // BFECC (Kim et al. 2005): forward, backward, then forward again from the corrected field.
  mForward.reshape(src.size());
  mBackward.reshape(src.size());
  pass(src, mForward, mBack, interpolation, nullptr, mask, background);        // φ̂
  pass(mForward, mBackward, mFore, interpolation, nullptr, mask, background);  // φ̄
  const std::size_t slice = std::size_t(src.size().x) * src.size().y;
  parallelFor(0, src.size().z, [&](int k) {
    // The error estimate ½(φ - φ̄) is added to φ before the final pass.
    for (std::size_t n = std::size_t(k) * slice, e = n + slice; n < e; ++n)
      mBackward[n] = src[n] + 0.5f * (src[n] - mBackward[n]);
  });
  // The limiter clamps to the range of the original φ so no new extrema appear.
  pass(mBackward, dst, mBack, interpolation, &src, mask, background);
}

}  // namespace plume
