/// \file field_sampler.cpp
/// Four- and eight-lane trilinear samples of the toon fields ([Cartoon Smoke] §2.1), both
/// equal to sampleLinear / sampleVelocity lane by lane (see the header).

#include "toon/field_sampler.h"

#include <smmintrin.h>

#include <algorithm>
#include <cstdint>

#include "core/cpu_features.h"
#include "core/linear_cells.h"
#include "core/sample_points.h"

namespace plume {
namespace {

/// Lower sample index and fraction of four coordinates clamped to [0, n-1]
/// (core/sample_points.h splitCoordinate4, the split of every Plume sample; NaN reads as 0).
struct AxisSplit4 {
  __m128i i;
  __m128 t;
  AxisSplit4() = default;
  AxisSplit4(__m128 x, int n) {
    splitCoordinate4(_mm_blendv_ps(x, _mm_setzero_ps(), _mm_cmpunord_ps(x, x)), n, i, t);
  }
};

/// The splits of four positions (lanes h .. h+3 of c): centred for the cell grids, staggered
/// (c + ½ on n + 1 faces) for the faces.
struct PositionSplits4 {
  AxisSplit4 centred[3];
  AxisSplit4 staggered[3];
  PositionSplits4(glm::ivec3 n, const ToonLanes3& c, int h) {
    for (int a = 0; a < 3; ++a) {
      const __m128 x = _mm_loadu_ps(c.c[a] + h);
      centred[a] = AxisSplit4(x, n[a]);
      staggered[a] = AxisSplit4(_mm_add_ps(x, _mm_set1_ps(0.5f)), n[a] + 1);
    }
  }
};

/// Trilinear samples of g at four stencils (x, y, z): sampleLinear's arithmetic on each lane.
__m128 trilinear4(const ScalarGrid& g, const AxisSplit4& x, const AxisSplit4& y,
                  const AxisSplit4& z) {
  const Neighbours d(g);
  alignas(16) int ix[4], iy[4], iz[4];
  _mm_store_si128(reinterpret_cast<__m128i*>(ix), x.i);
  _mm_store_si128(reinterpret_cast<__m128i*>(iy), y.i);
  _mm_store_si128(reinterpret_cast<__m128i*>(iz), z.i);
  // f[corner][lane], corner bits: x, y, z.
  alignas(16) float f[8][4];
  for (int m = 0; m < 4; ++m) {
    const float* q = g.data() + g.index(ix[m], iy[m], iz[m]);
    f[0][m] = q[0];
    f[1][m] = q[d.dx];
    f[2][m] = q[d.dy];
    f[3][m] = q[d.dy + d.dx];
    f[4][m] = q[d.dz];
    f[5][m] = q[d.dz + d.dx];
    f[6][m] = q[d.dz + d.dy];
    f[7][m] = q[d.dz + d.dy + d.dx];
  }
  auto lerp = [](__m128 a, __m128 b, __m128 t) {
    return _mm_add_ps(a, _mm_mul_ps(t, _mm_sub_ps(b, a)));
  };
  auto at = [&](int c) { return _mm_load_ps(f[c]); };
  const __m128 c00 = lerp(at(0), at(1), x.t), c10 = lerp(at(2), at(3), x.t);
  const __m128 c01 = lerp(at(4), at(5), x.t), c11 = lerp(at(6), at(7), x.t);
  return lerp(lerp(c00, c10, y.t), lerp(c01, c11, y.t), z.t);
}

/// The face velocity at four positions into lanes h .. h+3 of v.
void sampleFaces4(const MacGrid3& v, const PositionSplits4& s, ToonLanes3& out, int h) {
  _mm_storeu_ps(out.c[0] + h, trilinear4(v.u(), s.staggered[0], s.centred[1], s.centred[2]));
  _mm_storeu_ps(out.c[1] + h, trilinear4(v.v(), s.centred[0], s.staggered[1], s.centred[2]));
  _mm_storeu_ps(out.c[2] + h, trilinear4(v.w(), s.centred[0], s.centred[1], s.staggered[2]));
}

#if defined(PLUME_LINEAR_CELLS_AVX2)
#define PLUME_TOON_SAMPLER_AVX2 1

/// AxisSplit4 on eight lanes (core/sample_points.h splitCoordinate8).
struct AxisSplit8 {
  __m256i i;
  __m256 t;
};

__attribute__((target("avx2"))) inline AxisSplit8 axisSplit8(__m256 x, int n) {
  AxisSplit8 s;
  splitCoordinate8(_mm256_blendv_ps(x, _mm256_setzero_ps(), _mm256_cmp_ps(x, x, _CMP_UNORD_Q)), n,
                   s.i, s.t);
  return s;
}

/// PositionSplits4 of all eight lanes.
struct PositionSplits8 {
  AxisSplit8 centred[3];
  AxisSplit8 staggered[3];
};

__attribute__((target("avx2"))) inline PositionSplits8 positionSplits8(glm::ivec3 n,
                                                                       const ToonLanes3& c) {
  PositionSplits8 s;
  for (int a = 0; a < 3; ++a) {
    const __m256 x = _mm256_load_ps(c.c[a]);
    s.centred[a] = axisSplit8(x, n[a]);
    s.staggered[a] = axisSplit8(_mm256_add_ps(x, _mm256_set1_ps(0.5f)), n[a] + 1);
  }
  return s;
}

/// trilinear4 on eight lanes: the cells' corners gathered in pairs (cornersOf8), lerpCells8.
__attribute__((target("avx2"))) inline __m256 trilinear8(const ScalarGrid& g, const AxisSplit8& x,
                                                         const AxisSplit8& y, const AxisSplit8& z) {
  const __m256i index = _mm256_add_epi32(
      x.i, _mm256_add_epi32(_mm256_mullo_epi32(y.i, _mm256_set1_epi32(int(g.strideY()))),
                            _mm256_mullo_epi32(z.i, _mm256_set1_epi32(int(g.strideZ())))));
  alignas(32) std::uint32_t corner[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(corner), index);
  return lerpCells8(cornersOf8(g.data(), Neighbours(g), corner), x.t, y.t, z.t);
}

/// The face velocity at eight positions: component a into f[a].
__attribute__((target("avx2"))) inline void sampleFaces8(const MacGrid3& v,
                                                         const PositionSplits8& s, __m256* f) {
  f[0] = trilinear8(v.u(), s.staggered[0], s.centred[1], s.centred[2]);
  f[1] = trilinear8(v.v(), s.centred[0], s.staggered[1], s.centred[2]);
  f[2] = trilinear8(v.w(), s.centred[0], s.centred[1], s.staggered[2]);
}

__attribute__((target("avx2"))) void velocity8(const MacGrid3& a, const MacGrid3& b, float t,
                                               glm::ivec3 n, const ToonLanes3& c, ToonLanes3& v) {
  const PositionSplits8 s = positionSplits8(n, c);
  __m256 va[3];
  sampleFaces8(t >= 1.f ? b : a, s, va);
  if (t > 0.f && t < 1.f) {
    __m256 vb[3];
    sampleFaces8(b, s, vb);
    const __m256 wa = _mm256_set1_ps(1.f - t), wb = _mm256_set1_ps(t);
    for (int m = 0; m < 3; ++m)
      va[m] = _mm256_add_ps(_mm256_mul_ps(wa, va[m]), _mm256_mul_ps(wb, vb[m]));
  }
  for (int m = 0; m < 3; ++m) _mm256_store_ps(v.c[m], va[m]);
}

__attribute__((target("avx2"))) void fields8(const ToonFields& f, glm::ivec3 n, const ToonLanes3& c,
                                             ToonLanes3& v, float* density, float* temperature) {
  const PositionSplits8 s = positionSplits8(n, c);
  __m256 u[3];
  sampleFaces8(f.velocity, s, u);
  for (int m = 0; m < 3; ++m) _mm256_store_ps(v.c[m], u[m]);
  _mm256_storeu_ps(density, trilinear8(f.density, s.centred[0], s.centred[1], s.centred[2]));
  _mm256_storeu_ps(temperature,
                   f.temperature.count() == 0
                       ? _mm256_setzero_ps()
                       : trilinear8(f.temperature, s.centred[0], s.centred[1], s.centred[2]));
}

#endif

}  // namespace

ToonFieldSampler::ToonFieldSampler(glm::ivec3 cells, bool wide) : mCells(cells) {
#if defined(PLUME_TOON_SAMPLER_AVX2)
  // The eight-lane gathers index in 31 bits (the face grids have one more sample on an axis).
  const double samples = double(cells.x + 1) * double(cells.y + 1) * double(cells.z + 1);
  mWide = wide && hasAvx2() && samples < double(SamplePoints::kIndexMask);
#else
  (void)wide;
#endif
}

void ToonFieldSampler::velocity(const MacGrid3& a, const MacGrid3& b, float t,
                                const ToonLanes3& cell, ToonLanes3& v) const {
#if defined(PLUME_TOON_SAMPLER_AVX2)
  if (mWide) return velocity8(a, b, t, mCells, cell, v);
#endif
  for (int h = 0; h < kToonLanes; h += 4) {
    const PositionSplits4 s(mCells, cell, h);
    if (t <= 0.f || t >= 1.f) {
      sampleFaces4(t <= 0.f ? a : b, s, v, h);
      continue;
    }
    ToonLanes3 va, vb;
    sampleFaces4(a, s, va, h);
    sampleFaces4(b, s, vb, h);
    for (int m = 0; m < 3; ++m)
      for (int l = h; l < h + 4; ++l) v.c[m][l] = (1.f - t) * va.c[m][l] + t * vb.c[m][l];
  }
}

void ToonFieldSampler::fields(const ToonFields& f, const ToonLanes3& cell, ToonLanes3& v,
                              float* density, float* temperature) const {
#if defined(PLUME_TOON_SAMPLER_AVX2)
  if (mWide) return fields8(f, mCells, cell, v, density, temperature);
#endif
  for (int h = 0; h < kToonLanes; h += 4) {
    const PositionSplits4 s(mCells, cell, h);
    sampleFaces4(f.velocity, s, v, h);
    _mm_storeu_ps(density + h, trilinear4(f.density, s.centred[0], s.centred[1], s.centred[2]));
    if (f.temperature.count() != 0)
      _mm_storeu_ps(temperature + h,
                    trilinear4(f.temperature, s.centred[0], s.centred[1], s.centred[2]));
    else
      std::fill(temperature + h, temperature + h + 4, 0.f);
  }
}

}  // namespace plume
