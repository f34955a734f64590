#include "core/sampling.h"

#include "core/sample_points.h"

#include <cmath>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace plume {
namespace {

/// Integer cell and fraction of a coordinate clamped into [0, n-1].
inline void split(float x, int n, int& i, float& t) { splitCoordinate(x, n, i, t); }

/// Cell and fractions of p in g's index space.
struct Split {
  int i, j, k;
  float tx, ty, tz;
};
inline Split splitPoint(const ScalarGrid& g, glm::vec3 p) {
  const glm::ivec3 n = g.size();
  Split s;
  split(p.x, n.x, s.i, s.tx);
  split(p.y, n.y, s.j, s.ty);
  split(p.z, n.z, s.k, s.tz);
  return s;
}

/// True when the samples (i+lo .. i+hi) on every axis all lie inside the grid: the stencil can
/// then be read by pointer offsets, with no clamping.
inline bool stencilInside(const ScalarGrid& g, const Split& s, int lo, int hi) {
  const glm::ivec3 n = g.size();
  return s.i + lo >= 0 && s.j + lo >= 0 && s.k + lo >= 0 && s.i + hi < n.x && s.j + hi < n.y &&
         s.k + hi < n.z;
}

/// Fedkiw 2001 eq. 12-13 on one lane (the reference form; the SSE kernel below computes the same
/// operations in the same order, so both give bit-identical results).
inline float cubic1D(float f0, float f1, float f2, float f3, float t) {
  const float delta = f2 - f1;
  float d1 = 0.5f * (f2 - f0);
  float d2 = 0.5f * (f3 - f1);
  // Slopes must share the sign of Δ (Fedkiw 2001); |d| <= 3|Δ| keeps the Hermite cubic monotone.
  // A flat interval (Δ = 0) fails the sign test, so both slopes become zero there.
  const float lim = 3.f * std::fabs(delta);
  d1 = d1 * delta > 0.f ? std::copysign(std::fmin(std::fabs(d1), lim), delta) : 0.f;
  d2 = d2 * delta > 0.f ? std::copysign(std::fmin(std::fabs(d2), lim), delta) : 0.f;
  const float t2 = t * t, t3 = t2 * t;
  // f(t) = a3 t^3 + a2 t^2 + d1 t + f1.
  const float a3 = d1 + d2 - 2.f * delta;
  const float a2 = 3.f * delta - 2.f * d1 - d2;
  const float value = a3 * t3 + a2 * t2 + d1 * t + f1;
  // Exact arithmetic keeps the value between f1 and f2; the clamp also rules out rounding.
  const float lo = f1 < f2 ? f1 : f2, hi = f1 < f2 ? f2 : f1;
  return value < lo ? lo : (value > hi ? hi : value);
}

/// Monotonic cubic of a 4×4×4 stencil: x along rows (4 consecutive floats), then y, then z.
/// `base` points at stencil sample (0,0,0), sy/sz are the strides of y and z.
#if defined(__SSE2__)

/// cubic1D on four lanes at once.
inline __m128 cubic1D(__m128 f0, __m128 f1, __m128 f2, __m128 f3, __m128 t) {
  const __m128 sign = _mm_set1_ps(-0.f);
  const __m128 zero = _mm_setzero_ps();
  const __m128 delta = _mm_sub_ps(f2, f1);
  const __m128 signDelta = _mm_and_ps(delta, sign);
  const __m128 lim = _mm_mul_ps(_mm_set1_ps(3.f), _mm_andnot_ps(sign, delta));
  __m128 d1 = _mm_mul_ps(_mm_set1_ps(0.5f), _mm_sub_ps(f2, f0));
  __m128 d2 = _mm_mul_ps(_mm_set1_ps(0.5f), _mm_sub_ps(f3, f1));
  // d = d·Δ > 0 ? copysign(min(|d|, 3|Δ|), Δ) : 0
  const __m128 ok1 = _mm_cmpgt_ps(_mm_mul_ps(d1, delta), zero);
  const __m128 ok2 = _mm_cmpgt_ps(_mm_mul_ps(d2, delta), zero);
  d1 = _mm_and_ps(ok1, _mm_or_ps(_mm_min_ps(_mm_andnot_ps(sign, d1), lim), signDelta));
  d2 = _mm_and_ps(ok2, _mm_or_ps(_mm_min_ps(_mm_andnot_ps(sign, d2), lim), signDelta));
  const __m128 t2 = _mm_mul_ps(t, t), t3 = _mm_mul_ps(t2, t);
  const __m128 a3 = _mm_sub_ps(_mm_add_ps(d1, d2), _mm_mul_ps(_mm_set1_ps(2.f), delta));
  const __m128 a2 = _mm_sub_ps(
      _mm_sub_ps(_mm_mul_ps(_mm_set1_ps(3.f), delta), _mm_mul_ps(_mm_set1_ps(2.f), d1)), d2);
  const __m128 value = _mm_add_ps(
      _mm_add_ps(_mm_add_ps(_mm_mul_ps(a3, t3), _mm_mul_ps(a2, t2)), _mm_mul_ps(d1, t)), f1);
  // Same selections as the scalar clamp: lo = f1<f2 ? f1 : f2, hi = f1<f2 ? f2 : f1.
  const __m128 lo = _mm_min_ps(f1, f2), hi = _mm_max_ps(f2, f1);
  return _mm_max_ps(lo, _mm_min_ps(hi, value));
}

/// Four x-rows r0..r3 (4 floats each) → cubic along x for each row, one row per lane.
inline __m128 rowsCubic(const float* r0, const float* r1, const float* r2, const float* r3,
                        __m128 t) {
  __m128 a = _mm_loadu_ps(r0), b = _mm_loadu_ps(r1), c = _mm_loadu_ps(r2), d = _mm_loadu_ps(r3);
  _MM_TRANSPOSE4_PS(a, b, c, d);  // now a = f0 of each row, b = f1, ...
  return cubic1D(a, b, c, d, t);
}

/// The x and y passes of a 4×4×4 stencil: lane c of the result is the value at (tx, ty) in
/// z-layer c, ready for the last cubic along z.
inline __m128 stencilXY(const float* base, std::ptrdiff_t sy, std::ptrdiff_t sz, float tx,
                        float ty) {
  const __m128 vx = _mm_set1_ps(tx);
  // ys[c] holds, per lane b, the x-cubic of row (b, c).
  __m128 ys[4];
  for (int c = 0; c < 4; ++c) {
    const float* r = base + c * sz;
    ys[c] = rowsCubic(r, r + sy, r + 2 * sy, r + 3 * sy, vx);
  }
  _MM_TRANSPOSE4_PS(ys[0], ys[1], ys[2], ys[3]);  // ys[b] now holds lane c
  return cubic1D(ys[0], ys[1], ys[2], ys[3], _mm_set1_ps(ty));
}

#if defined(__x86_64__) && defined(__GNUC__) && !defined(PLUME_NO_AVX2)
#define PLUME_AVX2_DISPATCH 1

/// cubic1D on eight lanes (AVX2 build of the same operations, same order).
__attribute__((target("avx2"))) inline __m256 cubic1D(__m256 f0, __m256 f1, __m256 f2,
                                                       __m256 f3, __m256 t) {
  const __m256 sign = _mm256_set1_ps(-0.f);
  const __m256 zero = _mm256_setzero_ps();
  const __m256 delta = _mm256_sub_ps(f2, f1);
  const __m256 signDelta = _mm256_and_ps(delta, sign);
  const __m256 lim = _mm256_mul_ps(_mm256_set1_ps(3.f), _mm256_andnot_ps(sign, delta));
  __m256 d1 = _mm256_mul_ps(_mm256_set1_ps(0.5f), _mm256_sub_ps(f2, f0));
  __m256 d2 = _mm256_mul_ps(_mm256_set1_ps(0.5f), _mm256_sub_ps(f3, f1));
  const __m256 ok1 = _mm256_cmp_ps(_mm256_mul_ps(d1, delta), zero, _CMP_GT_OQ);
  const __m256 ok2 = _mm256_cmp_ps(_mm256_mul_ps(d2, delta), zero, _CMP_GT_OQ);
  d1 = _mm256_and_ps(ok1, _mm256_or_ps(_mm256_min_ps(_mm256_andnot_ps(sign, d1), lim), signDelta));
  d2 = _mm256_and_ps(ok2, _mm256_or_ps(_mm256_min_ps(_mm256_andnot_ps(sign, d2), lim), signDelta));
  const __m256 t2 = _mm256_mul_ps(t, t), t3 = _mm256_mul_ps(t2, t);
  const __m256 a3 = _mm256_sub_ps(_mm256_add_ps(d1, d2), _mm256_mul_ps(_mm256_set1_ps(2.f), delta));
  const __m256 a2 = _mm256_sub_ps(_mm256_sub_ps(_mm256_mul_ps(_mm256_set1_ps(3.f), delta),
                                                _mm256_mul_ps(_mm256_set1_ps(2.f), d1)),
                                  d2);
  const __m256 value = _mm256_add_ps(
      _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(a3, t3), _mm256_mul_ps(a2, t2)),
                    _mm256_mul_ps(d1, t)),
      f1);
  const __m256 lo = _mm256_min_ps(f1, f2), hi = _mm256_max_ps(f2, f1);
  return _mm256_max_ps(lo, _mm256_min_ps(hi, value));
}

/// The x pass on eight rows at once: rows (b, c) in the low half of each register and (b, c+1)
/// in the high half, transposed within each half, so that ys[b] holds, per lane c, the x-cubic
/// of row (b, c).
__attribute__((target("avx2"))) inline void stencilXAvx2(const float* base, std::ptrdiff_t sy,
                                                         std::ptrdiff_t sz, float tx,
                                                         __m128* ys) {
  const __m256 vx = _mm256_set1_ps(tx);
  for (int c = 0; c < 4; c += 2) {
    __m256 r[4];
    for (int b = 0; b < 4; ++b) {
      const float* row = base + b * sy + c * sz;
      r[b] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(row)),
                                  _mm_loadu_ps(row + sz), 1);
    }
    const __m256 t0 = _mm256_unpacklo_ps(r[0], r[1]), t1 = _mm256_unpacklo_ps(r[2], r[3]);
    const __m256 t2 = _mm256_unpackhi_ps(r[0], r[1]), t3 = _mm256_unpackhi_ps(r[2], r[3]);
    const __m256 y = cubic1D(_mm256_shuffle_ps(t0, t1, 0x44), _mm256_shuffle_ps(t0, t1, 0xEE),
                             _mm256_shuffle_ps(t2, t3, 0x44), _mm256_shuffle_ps(t2, t3, 0xEE), vx);
    ys[c] = _mm256_castps256_ps128(y);
    ys[c + 1] = _mm256_extractf128_ps(y, 1);
  }
  _MM_TRANSPOSE4_PS(ys[0], ys[1], ys[2], ys[3]);
}

/// stencilXY() with the x pass of stencilXAvx2().
__attribute__((target("avx2"))) __m128 stencilXYAvx2(const float* base, std::ptrdiff_t sy,
                                                     std::ptrdiff_t sz, float tx, float ty) {
  __m128 ys[4];
  stencilXAvx2(base, sy, sz, tx, ys);
  return cubic1D(ys[0], ys[1], ys[2], ys[3], _mm_set1_ps(ty));
}

/// The stencils of four split points (SamplePoints layout: index with kNearSide, fractions) in
/// one AVX2 function (no call per sample): x passes as in stencilXYAvx2(), the y cubics of two
/// samples in one 8-lane register, the z cubics of all four in one 4-lane register. Every lane
/// sees the operations of the SSE form, in the same order, so the values are bit-identical.
/// Stencils that leave the grid (kNearSide) give lane 0 for the caller to redo.
__attribute__((target("avx2"))) void cubic4Avx2(const ScalarGrid& g, const std::uint32_t* index,
                                                const float* tx, const float* ty,
                                                const float* tz, float* out) {
  const std::ptrdiff_t sy = g.strideY(), sz = g.strideZ();
  __m128 zs[4];
  for (int m = 0; m < 4; m += 2) {
    __m128 ys[2][4];
    for (int h = 0; h < 2; ++h) {
      if (!(index[m + h] & SamplePoints::kNearSide)) {
        stencilXAvx2(g.data() + std::ptrdiff_t(index[m + h]) - 1 - sy - sz, sy, sz, tx[m + h],
                     ys[h]);
      } else {
        for (int b = 0; b < 4; ++b) ys[h][b] = _mm_setzero_ps();
      }
    }
    __m256 y[4];
    for (int b = 0; b < 4; ++b) y[b] = _mm256_insertf128_ps(_mm256_castps128_ps256(ys[0][b]), ys[1][b], 1);
    const __m256 t = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_set1_ps(ty[m])),
                                          _mm_set1_ps(ty[m + 1]), 1);
    const __m256 z = cubic1D(y[0], y[1], y[2], y[3], t);
    zs[m] = _mm256_castps256_ps128(z);
    zs[m + 1] = _mm256_extractf128_ps(z, 1);
  }
  _MM_TRANSPOSE4_PS(zs[0], zs[1], zs[2], zs[3]);
  _mm_storeu_ps(out, cubic1D(zs[0], zs[1], zs[2], zs[3], _mm_loadu_ps(tz)));
}

/// Chosen once per process: AVX2 where the CPU has it (same results, fewer instructions).
const bool kHasAvx2 = hasAvx2();

#endif

/// stencilXY() with the widest instructions this CPU has.
inline __m128 stencilXYBest(const float* base, std::ptrdiff_t sy, std::ptrdiff_t sz, float tx,
                            float ty) {
#if defined(PLUME_AVX2_DISPATCH)
  if (kHasAvx2) return stencilXYAvx2(base, sy, sz, tx, ty);
#endif
  return stencilXY(base, sy, sz, tx, ty);
}

/// The last cubic along z of one stencil, on broadcast lanes: branch-free like the others (the
/// scalar form's sign tests mispredict on noisy data).
float stencilCubic(const float* base, std::ptrdiff_t sy, std::ptrdiff_t sz, float tx, float ty,
                   float tz) {
  const __m128 zs = stencilXYBest(base, sy, sz, tx, ty);
  const __m128 v = cubic1D(_mm_shuffle_ps(zs, zs, 0x00), _mm_shuffle_ps(zs, zs, 0x55),
                           _mm_shuffle_ps(zs, zs, 0xAA), _mm_shuffle_ps(zs, zs, 0xFF),
                           _mm_set1_ps(tz));
  return _mm_cvtss_f32(v);
}

#else

float stencilCubic(const float* base, std::ptrdiff_t sy, std::ptrdiff_t sz, float tx, float ty,
                   float tz) {
  float zs[4];
  for (int c = 0; c < 4; ++c) {
    float ys[4];
    for (int b = 0; b < 4; ++b) {
      const float* r = base + b * sy + c * sz;
      ys[b] = cubic1D(r[0], r[1], r[2], r[3], tx);
    }
    zs[c] = cubic1D(ys[0], ys[1], ys[2], ys[3], ty);
  }
  return cubic1D(zs[0], zs[1], zs[2], zs[3], tz);
}

#endif

}  // namespace

float sampleLinear(const ScalarGrid& g, glm::vec3 p) {
  const glm::ivec3 n = g.size();
  const Split s = splitPoint(g, p);
  // After split() the +1 neighbour exists on every axis longer than one sample.
  const std::ptrdiff_t dx = n.x > 1 ? 1 : 0;
  const std::ptrdiff_t dy = n.y > 1 ? g.strideY() : 0;
  const std::ptrdiff_t dz = n.z > 1 ? g.strideZ() : 0;
  const float* q = g.data() + g.index(s.i, s.j, s.k);
  const float c00 = q[0] + s.tx * (q[dx] - q[0]);
  const float c10 = q[dy] + s.tx * (q[dy + dx] - q[dy]);
  const float c01 = q[dz] + s.tx * (q[dz + dx] - q[dz]);
  const float c11 = q[dz + dy] + s.tx * (q[dz + dy + dx] - q[dz + dy]);
  const float c0 = c00 + s.ty * (c10 - c00);
  const float c1 = c01 + s.ty * (c11 - c01);
  return c0 + s.tz * (c1 - c0);
}

float monotonicCubic1D(float f0, float f1, float f2, float f3, float t) {
  return cubic1D(f0, f1, f2, f3, t);
}

float sampleMonotonicCubic(const ScalarGrid& g, glm::vec3 p) {
  const Split s = splitPoint(g, p);
  if (stencilInside(g, s, -1, 2))  // fast path: read the 4×4×4 stencil in place
    return stencilCubic(g.data() + g.index(s.i - 1, s.j - 1, s.k - 1), g.strideY(), g.strideZ(),
                        s.tx, s.ty, s.tz);
  // Near the sides: copy the stencil with clamped indices (constant extrapolation).
  const glm::ivec3 n = g.size();
  std::ptrdiff_t xs[4], ys[4], zs[4];
  for (int a = 0; a < 4; ++a) {
    xs[a] = glm::clamp(s.i - 1 + a, 0, n.x - 1);
    ys[a] = glm::clamp(s.j - 1 + a, 0, n.y - 1) * g.strideY();
    zs[a] = glm::clamp(s.k - 1 + a, 0, n.z - 1) * g.strideZ();
  }
  float block[64];
  for (int c = 0; c < 4; ++c)
    for (int b = 0; b < 4; ++b) {
      const float* row = g.data() + zs[c] + ys[b];
      for (int a = 0; a < 4; ++a) block[a + 4 * (b + 4 * c)] = row[xs[a]];
    }
  return stencilCubic(block, 4, 16, s.tx, s.ty, s.tz);
}

namespace {

/// Monotonic cubic samples of four split points (SamplePoints layout) into out[0..3], lane 0
/// for the points flagged kNearSide (the caller redoes those from their positions).
void cubic4Split(const ScalarGrid& g, const std::uint32_t* index, const float* tx,
                 const float* ty, const float* tz, float* out) {
#if defined(PLUME_AVX2_DISPATCH)
  if (kHasAvx2) {
    cubic4Avx2(g, index, tx, ty, tz, out);
    return;
  }
#endif
#if defined(__SSE2__)
  // x and y per sample, then the four z cubics in one register (lane = sample).
  __m128 zs[4];
  for (int m = 0; m < 4; ++m)
    zs[m] = index[m] & SamplePoints::kNearSide
                ? _mm_setzero_ps()
                : stencilXYBest(g.data() + std::ptrdiff_t(index[m]) - 1 - g.strideY() - g.strideZ(),
                                g.strideY(), g.strideZ(), tx[m], ty[m]);
  _MM_TRANSPOSE4_PS(zs[0], zs[1], zs[2], zs[3]);  // zs[c] now holds lane m
  _mm_storeu_ps(out, cubic1D(zs[0], zs[1], zs[2], zs[3], _mm_loadu_ps(tz)));
#else
  for (int m = 0; m < 4; ++m) {
    const std::ptrdiff_t c = std::ptrdiff_t(index[m]) - 1 - g.strideY() - g.strideZ();
    out[m] = index[m] & SamplePoints::kNearSide
                 ? 0.f
                 : stencilCubic(g.data() + c, g.strideY(), g.strideZ(), tx[m], ty[m], tz[m]);
  }
#endif
}

}  // namespace

void sampleMonotonicCubic4(const ScalarGrid& g, const glm::vec3* p, float* out) {
  // Split the four points as SamplePoints::set() does, then the shared kernel.
  std::uint32_t index[4];
  float t[3][4];
  for (int m = 0; m < 4; ++m) {
    const Split s = splitPoint(g, p[m]);
    index[m] = std::uint32_t(g.index(s.i, s.j, s.k)) |
               (stencilInside(g, s, -1, 2) ? 0u : SamplePoints::kNearSide);
    t[0][m] = s.tx;
    t[1][m] = s.ty;
    t[2][m] = s.tz;
  }
  cubic4Split(g, index, t[0], t[1], t[2], out);
  for (int m = 0; m < 4; ++m)
    if (index[m] & SamplePoints::kNearSide) out[m] = sampleMonotonicCubic(g, p[m]);  // near the sides
}

void sampleMonotonicCubic(const ScalarGrid& g, const SamplePoints& points, std::size_t first,
                          int count, float* out) {
  const std::uint32_t* index = points.index() + first;
  int m = 0;
  for (; m + 4 <= count; m += 4)
    cubic4Split(g, index + m, points.tx() + first + m, points.ty() + first + m,
                points.tz() + first + m, out + m);
  for (int r = 0; r < m; ++r)
    if (index[r] & SamplePoints::kNearSide)
      out[r] = sampleMonotonicCubic(g, points.position(first + std::size_t(r)));  // near the sides
  for (; m < count; ++m) out[m] = sampleMonotonicCubic(g, points.position(first + std::size_t(m)));
}

void sampleRange(const ScalarGrid& g, glm::vec3 p, float& lo, float& hi) {
  const glm::ivec3 n = g.size();
  const Split s = splitPoint(g, p);
  // Same neighbours as sampleLinear: the +1 sample on every axis longer than one.
  const std::ptrdiff_t dx = n.x > 1 ? 1 : 0;
  const std::ptrdiff_t dy = n.y > 1 ? g.strideY() : 0;
  const std::ptrdiff_t dz = n.z > 1 ? g.strideZ() : 0;
  const float* q = g.data() + g.index(s.i, s.j, s.k);
  const float f[8] = {q[0],      q[dx],      q[dy],      q[dy + dx],
                      q[dz],     q[dz + dx], q[dz + dy], q[dz + dy + dx]};
  lo = hi = f[0];
  for (int m = 1; m < 8; ++m) {
    lo = f[m] < lo ? f[m] : lo;
    hi = f[m] > hi ? f[m] : hi;
  }
}

glm::vec3 sampleVelocity(const MacGrid3& vel, glm::vec3 p) {
  // u(i,j,k) sits at cell coordinates (i - 1/2, j, k): shift p into each component's index space.
  return {sampleLinear(vel.u(), p + glm::vec3(0.5f, 0.f, 0.f)),
          sampleLinear(vel.v(), p + glm::vec3(0.f, 0.5f, 0.f)),
          sampleLinear(vel.w(), p + glm::vec3(0.f, 0.f, 0.5f))};
}

glm::vec3 sampleVelocity(const MacGrid3& vel, glm::vec3 p, Interpolation scheme) {
  return {sample(vel.u(), p + glm::vec3(0.5f, 0.f, 0.f), scheme),
          sample(vel.v(), p + glm::vec3(0.f, 0.5f, 0.f), scheme),
          sample(vel.w(), p + glm::vec3(0.f, 0.f, 0.5f), scheme)};
}

}  // namespace plume
