#include "solver/advection.h"

#include "core/parallel.h"

#if defined(__SSE4_1__)
#include <immintrin.h>
#endif

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

/// Cell and fraction of coordinate x on an axis of n samples: split() of core/sampling.cpp.
inline void splitAxis(float x, int n, int& i, float& t) {
  const float hi = float(n - 1);
  x = x < 0.f ? 0.f : (x > hi ? hi : x);
  i = int(x);
  if (i >= n - 1) i = n > 1 ? n - 2 : 0;
  t = x - float(i);
}

/// sampleLinear() of g from an already split position (same operations, same order).
inline float lerpAt(const ScalarGrid& g, int i, int j, int k, float tx, float ty, float tz) {
  const glm::ivec3 n = g.size();
  const std::ptrdiff_t dx = n.x > 1 ? 1 : 0;
  const std::ptrdiff_t dy = n.y > 1 ? g.strideY() : 0;
  const std::ptrdiff_t dz = n.z > 1 ? g.strideZ() : 0;
  const float* q = g.data() + g.index(i, j, k);
  const float c00 = q[0] + tx * (q[dx] - q[0]);
  const float c10 = q[dy] + tx * (q[dy + dx] - q[dy]);
  const float c01 = q[dz] + tx * (q[dz + dx] - q[dz]);
  const float c11 = q[dz + dy] + tx * (q[dz + dy + dx] - q[dz + dy]);
  const float c0 = c00 + ty * (c10 - c00);
  const float c1 = c01 + ty * (c11 - c01);
  return c0 + tz * (c1 - c0);
}

/// sampleVelocity(velocity, p), bit for bit, with 6 axis splits instead of 9: along each axis
/// the two components not staggered on it share the cell-centred split.
inline glm::vec3 sampleVelocityShared(const MacGrid3& velocity, glm::vec3 p) {
  const glm::ivec3 n = velocity.cells();
  int c[3], f[3];  // cell-centred and face-centred cell of each axis
  float tc[3], tf[3];
  for (int a = 0; a < 3; ++a) {
    splitAxis(p[a], n[a], c[a], tc[a]);
    splitAxis(p[a] + 0.5f, n[a] + 1, f[a], tf[a]);
  }
  return {lerpAt(velocity.u(), f[0], c[1], c[2], tf[0], tc[1], tc[2]),
          lerpAt(velocity.v(), c[0], f[1], c[2], tc[0], tf[1], tc[2]),
          lerpAt(velocity.w(), c[0], c[1], f[2], tc[0], tc[1], tf[2])};
}

#if defined(__SSE4_1__)
/// sampleVelocityShared() at four points (one per lane of px, py, pz): the splits and lerps on
/// four lanes, each lane with the operations of the scalar form in the same order, so the values
/// are bit-identical to it (the clamps select like split(); lanes differ at most in the sign of a
/// zero fraction, which no position depends on).
struct VelocityLanes {
  __m128 x, y, z;
};
inline VelocityLanes sampleVelocity4(const MacGrid3& velocity, __m128 px, __m128 py, __m128 pz) {
  const glm::ivec3 n = velocity.cells();
  const __m128 pos[3] = {px, py, pz};
  __m128i c[3], f[3];
  __m128 tc[3], tf[3];
  auto splitLanes = [](__m128 x, int count, __m128i& i, __m128& t) {
    const __m128 zero = _mm_setzero_ps(), hi = _mm_set1_ps(float(count - 1));
    x = _mm_blendv_ps(x, zero, _mm_cmplt_ps(x, zero));
    x = _mm_blendv_ps(x, hi, _mm_cmpgt_ps(x, hi));
    i = _mm_cvttps_epi32(x);
    const __m128i last = _mm_cmpgt_epi32(i, _mm_set1_epi32(count - 2));  // i >= count - 1
    i = _mm_blendv_epi8(i, _mm_set1_epi32(count > 1 ? count - 2 : 0), last);
    t = _mm_sub_ps(x, _mm_cvtepi32_ps(i));
  };
  for (int a = 0; a < 3; ++a) {
    splitLanes(pos[a], n[a], c[a], tc[a]);
    splitLanes(_mm_add_ps(pos[a], _mm_set1_ps(0.5f)), n[a] + 1, f[a], tf[a]);
  }
  auto lerp = [](__m128 a, __m128 b, __m128 t) { return _mm_add_ps(a, _mm_mul_ps(t, _mm_sub_ps(b, a))); };
  auto component = [&](const ScalarGrid& g, __m128i i, __m128i j, __m128i k, __m128 tx,
                       __m128 ty, __m128 tz) {
    const glm::ivec3 s = g.size();
    const std::ptrdiff_t dx = s.x > 1 ? 1 : 0;
    const std::ptrdiff_t dy = s.y > 1 ? g.strideY() : 0;
    const std::ptrdiff_t dz = s.z > 1 ? g.strideZ() : 0;
    // Linear indices fit in 32 bits (SmokeParams caps the cell count).
    const __m128i index = _mm_add_epi32(
        i, _mm_mullo_epi32(_mm_set1_epi32(s.x),
                           _mm_add_epi32(j, _mm_mullo_epi32(_mm_set1_epi32(s.y), k))));
    alignas(16) std::int32_t at[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(at), index);
    const float* q[4] = {g.data() + at[0], g.data() + at[1], g.data() + at[2], g.data() + at[3]};
    auto load = [&](std::ptrdiff_t o) { return _mm_setr_ps(q[0][o], q[1][o], q[2][o], q[3][o]); };
    const __m128 c00 = lerp(load(0), load(dx), tx);
    const __m128 c10 = lerp(load(dy), load(dy + dx), tx);
    const __m128 c01 = lerp(load(dz), load(dz + dx), tx);
    const __m128 c11 = lerp(load(dz + dy), load(dz + dy + dx), tx);
    return lerp(lerp(c00, c10, ty), lerp(c01, c11, ty), tz);
  };
  return {component(velocity.u(), f[0], c[1], c[2], tf[0], tc[1], tc[2]),
          component(velocity.v(), c[0], f[1], c[2], tc[0], tf[1], tc[2]),
          component(velocity.w(), c[0], c[1], f[2], tc[0], tc[1], tf[2])};
}

/// traceBackFrom() at four points p with first velocities v1 (lanes), written to out[0..3]
/// minus `offset`: the same operations as the scalar form.
inline void traceBack4(const MacGrid3& velocity, const __m128* p, const __m128* v1, float cells,
                       glm::vec3 offset, glm::vec3* out) {
  const __m128 half = _mm_set1_ps(0.5f * cells), full = _mm_set1_ps(cells);
  const VelocityLanes v2 = sampleVelocity4(velocity, _mm_sub_ps(p[0], _mm_mul_ps(half, v1[0])),
                                           _mm_sub_ps(p[1], _mm_mul_ps(half, v1[1])),
                                           _mm_sub_ps(p[2], _mm_mul_ps(half, v1[2])));
  alignas(16) float r[3][4];
  _mm_store_ps(r[0], _mm_sub_ps(_mm_sub_ps(p[0], _mm_mul_ps(full, v2.x)), _mm_set1_ps(offset.x)));
  _mm_store_ps(r[1], _mm_sub_ps(_mm_sub_ps(p[1], _mm_mul_ps(full, v2.y)), _mm_set1_ps(offset.y)));
  _mm_store_ps(r[2], _mm_sub_ps(_mm_sub_ps(p[2], _mm_mul_ps(full, v2.z)), _mm_set1_ps(offset.z)));
  for (int m = 0; m < 4; ++m) out[m] = glm::vec3(r[0][m], r[1][m], r[2][m]);
}
#endif

/// traceBack() with the velocity v1 at p already known (BFECC's back and forth traces share it).
inline glm::vec3 traceBackFrom(const MacGrid3& velocity, glm::vec3 p, glm::vec3 v1, float cells) {
  const glm::vec3 mid = p - 0.5f * cells * v1;
  const glm::vec3 v2 = sampleVelocityShared(velocity, mid);
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
  // The first velocity sample of every trace sits on a sample of the traced grid, where each
  // velocity component is an exact average of 2 or 4 of its faces: its taps along every axis
  // depend on one index only, so they are tabulated once (see Taps) instead of split per sample.
  mTaps.build(velocity, size, offset);
  const float* u = velocity.u().data();
  const float* v = velocity.v().data();
  const float* w = velocity.w().data();
  const ScalarGrid* comps[3] = {&velocity.u(), &velocity.v(), &velocity.w()};
  forEachRun(
      size, mask,
      [&](int i0, int i1, int j, int k) {
        std::size_t c = std::size_t(i0) + std::size_t(size.x) * (std::size_t(j) + std::size_t(size.y) * k);
        // Row offsets and y/z fractions of each component, fixed along the row.
        std::ptrdiff_t row[3][4];
        float ty[3], tz[3];
        for (int a = 0; a < 3; ++a) {
          const Taps::Tap y = mTaps.at(a, 1, j), z = mTaps.at(a, 2, k);
          const std::ptrdiff_t sy = comps[a]->strideY(), sz = comps[a]->strideZ();
          row[a][0] = y.i * sy + z.i * sz;
          row[a][1] = row[a][0] + sy;
          row[a][2] = row[a][0] + sz;
          row[a][3] = row[a][0] + sy + sz;
          ty[a] = y.t;
          tz[a] = z.t;
        }
        const float* data[3] = {u, v, w};
        int i = i0;
#if defined(__SSE4_1__)
        // Four samples at a time; the rest of the run one by one.
        for (; i + 4 <= i1; i += 4, c += 4) {
          alignas(16) float v1[3][4];
          for (int m = 0; m < 4; ++m)
            for (int a = 0; a < 3; ++a) {
              const Taps::Tap x = mTaps.at(a, 0, i + m);
              v1[a][m] = Taps::lerp3(data[a] + x.i, row[a], x.t, ty[a], tz[a]);
            }
          const __m128 p[3] = {
              _mm_add_ps(_mm_setr_ps(float(i), float(i + 1), float(i + 2), float(i + 3)),
                         _mm_set1_ps(offset.x)),
              _mm_set1_ps(float(j) + offset.y), _mm_set1_ps(float(k) + offset.z)};
          const __m128 lanes[3] = {_mm_load_ps(v1[0]), _mm_load_ps(v1[1]), _mm_load_ps(v1[2])};
          traceBack4(velocity, p, lanes, cells, offset, &mBack[c]);
          if (both) traceBack4(velocity, p, lanes, -cells, offset, &mFore[c]);
        }
#endif
        for (; i < i1; ++i, ++c) {
          const glm::vec3 p = glm::vec3(i, j, k) + offset;
          glm::vec3 v1;
          for (int a = 0; a < 3; ++a) {
            const Taps::Tap x = mTaps.at(a, 0, i);
            v1[a] = Taps::lerp3(data[a] + x.i, row[a], x.t, ty[a], tz[a]);
          }
          // Positions are stored in the grid's own index space (cell coordinates - offset).
          mBack[c] = traceBackFrom(velocity, p, v1, cells) - offset;
          if (both) mFore[c] = traceBackFrom(velocity, p, v1, -cells) - offset;
        }
      },
      [](int, int, int, int) {});
}

void Advector::Taps::build(const MacGrid3& velocity, glm::ivec3 size, glm::vec3 offset) {
  for (int a = 0; a < 3; ++a) {
    const glm::ivec3 n = velocity.component(a).size();
    for (int d = 0; d < 3; ++d) {
      std::vector<Tap>& taps = mTaps[a][d];
      taps.resize(std::size_t(size[d]));
      // Sample m of the traced grid is at m + offset[d] in cell coordinates; component a's
      // samples sit half a cell lower along a.
      const float shift = offset[d] + (d == a ? 0.5f : 0.f);
      for (int m = 0; m < size[d]; ++m) {
        float x = float(m) + shift;
        // The clamping and cell choice of sampleLinear (core/sampling.cpp, split()).
        const float hi = float(n[d] - 1);
        x = x < 0.f ? 0.f : (x > hi ? hi : x);
        int i = int(x);
        if (i >= n[d] - 1) i = n[d] > 1 ? n[d] - 2 : 0;
        taps[std::size_t(m)] = {i, x - float(i)};
      }
    }
  }
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
