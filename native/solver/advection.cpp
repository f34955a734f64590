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

/// One semi-Lagrangian pass over traced positions: dst(x) = finish(c, src(trace(x))), c the
/// linear index of x. `finish` applies the corrections and limiters of BFECC and MacCormack.
template <typename Finish>
void pass(const ScalarGrid& src, ScalarGrid& dst, const std::vector<glm::vec3>& traced,
          Interpolation interpolation, const BlockMask* mask, float background,
          const Finish& finish) {
  // sampler(c, count, values) samples src at the `count` <= 4 traced points from index c on.
  auto runs = [&](const auto& sampler) {
    forEachRun(
        src.size(), mask,
        [&](int i0, int i1, int j, int k) {
          std::size_t c = src.index(i0, j, k);
          for (int i = i0; i < i1; i += 4, c += 4) {
            const int count = std::min(4, i1 - i);
            float values[4];
            sampler(c, count, values);
            for (int m = 0; m < count; ++m) dst[c + m] = finish(c + m, values[m]);
          }
        },
        [&](int i0, int i1, int j, int k) {
          std::size_t c = src.index(i0, j, k);
          for (int i = i0; i < i1; ++i, ++c) dst[c] = background;
        });
  };
  // The scheme is chosen once per pass, not per sample; cubic samples go four at a time.
  if (interpolation == Interpolation::Linear) {
    runs([&](std::size_t c, int count, float* values) {
      for (int m = 0; m < count; ++m) values[m] = sampleLinear(src, traced[c + m]);
    });
  } else {
    runs([&](std::size_t c, int count, float* values) {
      if (count == 4) sampleMonotonicCubic4(src, &traced[c], values);
      else
        for (int m = 0; m < count; ++m) values[m] = sampleMonotonicCubic(src, traced[c + m]);
    });
  }
}

/// The plain semi-Lagrangian value.
constexpr auto kAsIs = [](std::size_t, float value) { return value; };

/// value clamped to the range of φ around the back-traced point q (the limiter of BFECC and
/// MacCormack: no new extrema).
inline float clampToRange(const ScalarGrid& phi, glm::vec3 q, float value) {
  float lo, hi;
  sampleRange(phi, q, lo, hi);
  return value < lo ? lo : (value > hi ? hi : value);
}

/// traceBack() with the velocity v1 at p already known (BFECC's back and forth traces share it).
inline glm::vec3 traceBackFrom(const MacGrid3& velocity, glm::vec3 p, glm::vec3 v1, float cells) {
  const glm::vec3 mid = p - 0.5f * cells * v1;
  const glm::vec3 v2 = sampleVelocity(velocity, mid);
  return p - cells * v2;
}

}  // namespace

glm::vec3 traceBack(const MacGrid3& velocity, glm::vec3 p, float cells) {
  return traceBackFrom(velocity, p, sampleVelocity(velocity, p), cells);
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
  // BFECC and MacCormack also need the forward traces (their reverse step A⁻¹).
  const bool both = scheme != Advection::SemiLagrangian;
  if (both) mFore.resize(count);
  const float cells = dt / cellSize;
  forEachRun(
      size, mask,
      [&](int i0, int i1, int j, int k) {
        std::size_t c = std::size_t(i0) + std::size_t(size.x) * (std::size_t(j) + std::size_t(size.y) * k);
        for (int i = i0; i < i1; ++i, ++c) {
          const glm::vec3 p = glm::vec3(i, j, k) + offset;
          // Positions are stored in the grid's own index space (cell coordinates - offset).
          const glm::vec3 v1 = sampleVelocity(velocity, p);
          mBack[c] = traceBackFrom(velocity, p, v1, cells) - offset;
          if (both) mFore[c] = traceBackFrom(velocity, p, v1, -cells) - offset;
        }
      },
      [](int, int, int, int) {});
}

void Advector::advect(const ScalarGrid& src, ScalarGrid& dst, Interpolation interpolation,
                      const BlockMask* mask, float background) {
  dst.reshape(src.size());
  if (mScheme == Advection::SemiLagrangian) {
    pass(src, dst, mBack, interpolation, mask, background, kAsIs);
    return;
  }
  // φ̂ = A(φ): the semi-Lagrangian step along the back-traces.
  mForward.reshape(src.size());
  pass(src, mForward, mBack, interpolation, mask, background, kAsIs);
  if (mScheme == Advection::MacCormack) {
    // Selle et al. 2008 eq. 7: φ = φ̂ + ½(φⁿ - φ̄) with φ̄ = A⁻¹(φ̂), fused with the reverse step,
    // then clamped to the range of φⁿ around the back-traced point (§4, first limiter).
    pass(mForward, dst, mFore, interpolation, mask, background, [&](std::size_t c, float bar) {
      return clampToRange(src, mBack[c], mForward[c] + 0.5f * (src[c] - bar));
    });
    return;
  }
  // BFECC (Kim et al. 2005): φ̄ = A⁻¹(φ̂) and the corrected field φ + ½(φ - φ̄) in one pass...
  mBackward.reshape(src.size());
  pass(mForward, mBackward, mFore, interpolation, mask, background,
       [&](std::size_t c, float bar) { return src[c] + 0.5f * (src[c] - bar); });
  // ...then forward again from it, clamped to the range of the original φ (no new extrema).
  pass(mBackward, dst, mBack, interpolation, mask, background,
       [&](std::size_t c, float value) { return clampToRange(src, mBack[c], value); });
}

}  // namespace plume
