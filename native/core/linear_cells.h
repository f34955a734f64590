#pragma once
/// \file linear_cells.h
/// The trilinear cell of a split point (SamplePoints): its 8 corners, the trilinear value and
/// their range, one point at a time or eight at a time in AVX2 registers. Internal to the
/// sampling kernels of core/ and solver/; every form performs sampleLinear()'s and
/// sampleRange()'s operations in their order, so all give the same values bit for bit.

#include "core/sample_points.h"

#include <cstring>

namespace plume {

/// Offsets of the +1 neighbour along x, y, z: 0 on an axis of one sample (sampleLinear()).
struct Neighbours {
  std::ptrdiff_t dx, dy, dz;
  explicit Neighbours(const ScalarGrid& g)
      : dx(g.size().x > 1 ? 1 : 0), dy(g.size().y > 1 ? g.strideY() : 0),
        dz(g.size().z > 1 ? g.strideZ() : 0) {}
};

/// sampleLinear() from a split point: q points at the cell's lower corner.
inline float lerpCell(const float* q, const Neighbours& d, float tx, float ty, float tz) {
  const float c00 = q[0] + tx * (q[d.dx] - q[0]);
  const float c10 = q[d.dy] + tx * (q[d.dy + d.dx] - q[d.dy]);
  const float c01 = q[d.dz] + tx * (q[d.dz + d.dx] - q[d.dz]);
  const float c11 = q[d.dz + d.dy] + tx * (q[d.dz + d.dy + d.dx] - q[d.dz + d.dy]);
  const float c0 = c00 + ty * (c10 - c00);
  const float c1 = c01 + ty * (c11 - c01);
  return c0 + tz * (c1 - c0);
}

/// sampleRange() from a split point: smallest and largest corner, in sampleRange()'s order.
inline void rangeCell(const float* q, const Neighbours& d, float& lo, float& hi) {
  const float f[8] = {q[0],        q[d.dx],        q[d.dy],        q[d.dy + d.dx],
                      q[d.dz],     q[d.dz + d.dx], q[d.dz + d.dy], q[d.dz + d.dy + d.dx]};
  lo = hi = f[0];
  for (int m = 1; m < 8; ++m) {
    lo = f[m] < lo ? f[m] : lo;
    hi = f[m] > hi ? f[m] : hi;
  }
}

#if defined(__x86_64__) && defined(__GNUC__) && !defined(PLUME_NO_AVX2)
#define PLUME_LINEAR_CELLS_AVX2 1

/// The corners of the trilinear cells of eight points, corner m of point p in lane p of f[m],
/// corners in sampleRange()'s order.
struct Corners8 {
  __m256 f[8];
};

/// corners[0..3] of four points at lanes 0..3 of each half: (a0 a1 a2 a3 | b0 b1 b2 b3) with
/// a_p, b_p the 4 corners of points p and p+4, transposed within each 128-bit half.
__attribute__((target("avx2"))) inline void transposeHalves(const __m256* a, __m256* f) {
  const __m256 t0 = _mm256_unpacklo_ps(a[0], a[1]), t1 = _mm256_unpackhi_ps(a[0], a[1]);
  const __m256 t2 = _mm256_unpacklo_ps(a[2], a[3]), t3 = _mm256_unpackhi_ps(a[2], a[3]);
  f[0] = _mm256_shuffle_ps(t0, t2, 0x44);
  f[1] = _mm256_shuffle_ps(t0, t2, 0xEE);
  f[2] = _mm256_shuffle_ps(t1, t3, 0x44);
  f[3] = _mm256_shuffle_ps(t1, t3, 0xEE);
}

/// Corners of points index[0..7] (SamplePoints::index(), flags included) in `data`. The two x
/// neighbours of a corner pair are adjacent: each point loads 4 pairs (8 bytes each) and the
/// pairs are transposed in registers (measured faster than AVX2 gathers and than a transpose
/// through memory).
__attribute__((target("avx2"))) inline Corners8 cornersOf8(const float* data,
                                                           const Neighbours& d,
                                                           const std::uint32_t* index) {
  Corners8 c;
  if (d.dx != 1) {  // an axis of one sample: no pairs
    const std::ptrdiff_t offsets[8] = {0,    d.dx,        d.dy,        d.dy + d.dx,
                                       d.dz, d.dz + d.dx, d.dz + d.dy, d.dz + d.dy + d.dx};
    alignas(32) float t[8][8];
    for (int p = 0; p < 8; ++p) {
      const float* q = data + (index[p] & SamplePoints::kIndexMask);
      for (int m = 0; m < 8; ++m) t[m][p] = q[offsets[m]];
    }
    for (int m = 0; m < 8; ++m) c.f[m] = _mm256_load_ps(t[m]);
    return c;
  }
  auto pairs = [](const float* lo, const float* hi) {  // (lo[0] lo[1] hi[0] hi[1])
    double pair;  // two floats at any 4-byte address: read through memcpy, not a double*
    std::memcpy(&pair, lo, sizeof pair);
    return _mm_loadh_pi(_mm_castpd_ps(_mm_set_sd(pair)), reinterpret_cast<const __m64*>(hi));
  };
  __m128 r[2][8];  // r[0][p] = corners 0-3 of point p, r[1][p] = corners 4-7
  for (int p = 0; p < 8; ++p) {
    const float* q = data + (index[p] & SamplePoints::kIndexMask);
    r[0][p] = pairs(q, q + d.dy);
    r[1][p] = pairs(q + d.dz, q + d.dz + d.dy);
  }
  for (int h = 0; h < 2; ++h) {
    __m256 a[4];
    for (int p = 0; p < 4; ++p)
      a[p] = _mm256_insertf128_ps(_mm256_castps128_ps256(r[h][p]), r[h][p + 4], 1);
    transposeHalves(a, c.f + 4 * h);
  }
  return c;
}

/// a + t (b - a) on eight lanes (no FMA: this target does not enable it, nothing is contracted).
__attribute__((target("avx2"))) inline __m256 lerp8(__m256 a, __m256 b, __m256 t) {
  return _mm256_add_ps(a, _mm256_mul_ps(t, _mm256_sub_ps(b, a)));
}

/// lerpCell() on eight lanes with fractions x, y, z.
__attribute__((target("avx2"))) inline __m256 lerpCells8(const Corners8& c, __m256 x, __m256 y,
                                                         __m256 z) {
  const __m256 c00 = lerp8(c.f[0], c.f[1], x), c10 = lerp8(c.f[2], c.f[3], x);
  const __m256 c01 = lerp8(c.f[4], c.f[5], x), c11 = lerp8(c.f[6], c.f[7], x);
  return lerp8(lerp8(c00, c10, y), lerp8(c01, c11, y), z);
}

/// lerpCell() on eight lanes, fractions tx, ty, tz[0..7].
__attribute__((target("avx2"))) inline __m256 lerpCells8(const Corners8& c, const float* tx,
                                                         const float* ty, const float* tz) {
  return lerpCells8(c, _mm256_loadu_ps(tx), _mm256_loadu_ps(ty), _mm256_loadu_ps(tz));
}

/// rangeCell() on eight lanes: min_ps(f, lo) is "f < lo ? f : lo", max_ps(f, hi) "f > hi ? f : hi".
__attribute__((target("avx2"))) inline void rangeCells8(const Corners8& c, __m256& lo,
                                                        __m256& hi) {
  lo = hi = c.f[0];
  for (int m = 1; m < 8; ++m) {
    lo = _mm256_min_ps(c.f[m], lo);
    hi = _mm256_max_ps(c.f[m], hi);
  }
}

/// value < lo ? lo : (value > hi ? hi : value) on eight lanes, for lo <= hi (a range).
__attribute__((target("avx2"))) inline __m256 clamp8(__m256 value, __m256 lo, __m256 hi) {
  return _mm256_min_ps(hi, _mm256_max_ps(lo, value));
}

#endif

}  // namespace plume
