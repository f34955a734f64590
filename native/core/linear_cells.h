#pragma once
/// \file linear_cells.h
/// The trilinear cell of a split point (SamplePoints): its 8 corners, the trilinear value and
/// their range, one point at a time or eight at a time in AVX2 registers. Internal to the
/// sampling kernels of core/ and solver/; every form performs sampleLinear()'s and
/// sampleRange()'s operations in their order, so all give the same values bit for bit.

#include "core/sample_points.h"

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

/// Corners of points index[0..7] (SamplePoints::index(), flags included) in `data`. Loaded
/// one by one and transposed through the stack: on the CPUs measured this beats AVX2 gathers
/// (70 ms against 86 ms for the velocity passes of a 128³ step).
__attribute__((target("avx2"))) inline Corners8 cornersOf8(const float* data,
                                                           const Neighbours& d,
                                                           const std::uint32_t* index) {
  const std::ptrdiff_t offsets[8] = {0,    d.dx,        d.dy,        d.dy + d.dx,
                                     d.dz, d.dz + d.dx, d.dz + d.dy, d.dz + d.dy + d.dx};
  alignas(32) float t[8][8];
  for (int p = 0; p < 8; ++p) {
    const float* q = data + (index[p] & SamplePoints::kIndexMask);
    for (int m = 0; m < 8; ++m) t[m][p] = q[offsets[m]];
  }
  Corners8 c;
  for (int m = 0; m < 8; ++m) c.f[m] = _mm256_load_ps(t[m]);
  return c;
}

/// a + t (b - a) on eight lanes (no FMA: this target does not enable it, nothing is contracted).
__attribute__((target("avx2"))) inline __m256 lerp8(__m256 a, __m256 b, __m256 t) {
  return _mm256_add_ps(a, _mm256_mul_ps(t, _mm256_sub_ps(b, a)));
}

/// lerpCell() on eight lanes, fractions tx, ty, tz[0..7].
__attribute__((target("avx2"))) inline __m256 lerpCells8(const Corners8& c, const float* tx,
                                                         const float* ty, const float* tz) {
  const __m256 x = _mm256_loadu_ps(tx), y = _mm256_loadu_ps(ty), z = _mm256_loadu_ps(tz);
  const __m256 c00 = lerp8(c.f[0], c.f[1], x), c10 = lerp8(c.f[2], c.f[3], x);
  const __m256 c01 = lerp8(c.f[4], c.f[5], x), c11 = lerp8(c.f[6], c.f[7], x);
  return lerp8(lerp8(c00, c10, y), lerp8(c01, c11, y), z);
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
