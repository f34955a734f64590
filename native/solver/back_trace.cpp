#include "solver/back_trace.h"

#include "core/linear_cells.h"
#include "core/sampling.h"

namespace plume {
namespace {

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
    splitCoordinate(p[a], n[a], c[a], tc[a]);
    splitCoordinate(p[a] + 0.5f, n[a] + 1, f[a], tf[a]);
  }
  return {lerpAt(velocity.u(), f[0], c[1], c[2], tf[0], tc[1], tc[2]),
          lerpAt(velocity.v(), c[0], f[1], c[2], tc[0], tf[1], tc[2]),
          lerpAt(velocity.w(), c[0], c[1], f[2], tc[0], tc[1], tf[2])};
}

/// traceBack() with the velocity v1 at p already known (BFECC's back and forth traces share it).
inline glm::vec3 traceBackFrom(const MacGrid3& velocity, glm::vec3 p, glm::vec3 v1, float cells) {
  const glm::vec3 mid = p - 0.5f * cells * v1;
  const glm::vec3 v2 = sampleVelocityShared(velocity, mid);
  return p - cells * v2;
}

/// sampleLinear()'s lerps, x then y then z, skipping those with fraction 0 (which return their
/// first operand unchanged): q points at x-tap i of row 0; row[] holds the offsets of rows
/// (j,k), (j+1,k), (j,k+1), (j+1,k+1).
inline float lerp3(const float* q, const std::ptrdiff_t* row, float tx, float ty, float tz) {
  auto lx = [&](std::ptrdiff_t r) { return tx != 0.f ? q[r] + tx * (q[r + 1] - q[r]) : q[r]; };
  auto ly = [&](std::ptrdiff_t r0, std::ptrdiff_t r1) {
    const float a = lx(r0);
    return ty != 0.f ? a + ty * (lx(r1) - a) : a;
  };
  const float c0 = ly(row[0], row[1]);
  return tz != 0.f ? c0 + tz * (ly(row[2], row[3]) - c0) : c0;
}

#if defined(__SSE4_1__)
/// sampleVelocityShared() at four points (one per lane of px, py, pz): the splits and lerps on
/// four lanes, each lane with the operations of the scalar form in the same order, so the values
/// are bit-identical to it.
struct VelocityLanes {
  __m128 x, y, z;
};
inline VelocityLanes sampleVelocity4(const MacGrid3& velocity, __m128 px, __m128 py, __m128 pz) {
  const glm::ivec3 n = velocity.cells();
  const __m128 pos[3] = {px, py, pz};
  __m128i c[3], f[3];
  __m128 tc[3], tf[3];
  for (int a = 0; a < 3; ++a) {
    splitCoordinate4(pos[a], n[a], c[a], tc[a]);
    splitCoordinate4(_mm_add_ps(pos[a], _mm_set1_ps(0.5f)), n[a] + 1, f[a], tf[a]);
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

/// The traces of four samples p with first velocities v1 (lanes), minus `offset`, into points
/// n .. n+3 of `points`: p - cells·v(p - ½cells·v1) (midpoint) or p - cells·v1 (Euler), the operations of
/// the scalar forms.
inline void trace4(const MacGrid3& velocity, const __m128* p, const __m128* v1, float cells,
                   Trace order, glm::vec3 offset, PointSink& points, int n) {
  const __m128 full = _mm_set1_ps(cells);
  VelocityLanes v{v1[0], v1[1], v1[2]};
  if (order == Trace::Midpoint) {
    const __m128 half = _mm_set1_ps(0.5f * cells);
    v = sampleVelocity4(velocity, _mm_sub_ps(p[0], _mm_mul_ps(half, v1[0])),
                        _mm_sub_ps(p[1], _mm_mul_ps(half, v1[1])),
                        _mm_sub_ps(p[2], _mm_mul_ps(half, v1[2])));
  }
  points.set4(n, _mm_sub_ps(_mm_sub_ps(p[0], _mm_mul_ps(full, v.x)), _mm_set1_ps(offset.x)),
              _mm_sub_ps(_mm_sub_ps(p[1], _mm_mul_ps(full, v.y)), _mm_set1_ps(offset.y)),
              _mm_sub_ps(_mm_sub_ps(p[2], _mm_mul_ps(full, v.z)), _mm_set1_ps(offset.z)));
}
#endif

#if defined(PLUME_LINEAR_CELLS_AVX2)
#define PLUME_TRACE_AVX2 1

/// The x taps of eight consecutive samples of a row for one velocity component: consecutive
/// with one fraction (`uniform`, every run but those at the sides, where the taps clamp), or
/// one index and fraction per lane.
struct XTaps8 {
  bool uniform;
  const float* q;  ///< uniform: the component's data at the x tap of the first sample
  const float* data;
  alignas(32) std::int32_t i[8];  ///< per lane: x tap index (not uniform only)
  alignas(32) float t[8];         ///< per lane: fraction (uniform: t[0] only)
};

/// lerp3()'s x lerp of eight samples: a + t (b - a), or a where t is 0 (the scalar skip; a
/// uniform row skips as a whole, others choose per lane).
__attribute__((target("avx2"))) inline __m256 lerpX8(const XTaps8& x, std::ptrdiff_t r) {
  if (x.uniform) {
    const __m256 a = _mm256_loadu_ps(x.q + r);
    if (x.t[0] == 0.f) return a;
    return _mm256_add_ps(a, _mm256_mul_ps(_mm256_set1_ps(x.t[0]), _mm256_sub_ps(_mm256_loadu_ps(x.q + r + 1), a)));
  }
  const __m256 t = _mm256_load_ps(x.t);
  const __m256i i = _mm256_load_si256(reinterpret_cast<const __m256i*>(x.i));
  const __m256 a = _mm256_i32gather_ps(x.data + r, i, 4);
  const __m256 b = _mm256_i32gather_ps(x.data + r + 1, i, 4);
  const __m256 v = _mm256_add_ps(a, _mm256_mul_ps(t, _mm256_sub_ps(b, a)));
  return _mm256_blendv_ps(v, a, _mm256_cmp_ps(t, _mm256_setzero_ps(), _CMP_EQ_OQ));
}

/// lerp3()'s y lerp on eight lanes (ty is the row's: the skip is the scalar one).
__attribute__((target("avx2"))) inline __m256 lerpY8(const XTaps8& x, std::ptrdiff_t r0,
                                                     std::ptrdiff_t r1, float ty) {
  const __m256 a = lerpX8(x, r0);
  if (ty == 0.f) return a;
  return _mm256_add_ps(a, _mm256_mul_ps(_mm256_set1_ps(ty), _mm256_sub_ps(lerpX8(x, r1), a)));
}

/// lerp3() of eight samples of a row: the operations of the scalar form on each lane.
__attribute__((target("avx2"))) inline __m256 lerp3x8(const XTaps8& x, const std::ptrdiff_t* row,
                                                      float ty, float tz) {
  const __m256 c0 = lerpY8(x, row[0], row[1], ty);
  if (tz == 0.f) return c0;
  return _mm256_add_ps(c0, _mm256_mul_ps(_mm256_set1_ps(tz), _mm256_sub_ps(lerpY8(x, row[2], row[3], ty), c0)));
}

/// sampleVelocity4() on eight lanes (cornersOf8 for the loads), the same operations.
__attribute__((target("avx2"))) inline void sampleVelocity8(const MacGrid3& velocity,
                                                            const __m256* p, __m256* v) {
  const glm::ivec3 n = velocity.cells();
  __m256i c[3], f[3];
  __m256 tc[3], tf[3];
  for (int a = 0; a < 3; ++a) {
    splitCoordinate8(p[a], n[a], c[a], tc[a]);
    splitCoordinate8(_mm256_add_ps(p[a], _mm256_set1_ps(0.5f)), n[a] + 1, f[a], tf[a]);
  }
  for (int a = 0; a < 3; ++a) {
    const ScalarGrid& g = velocity.component(a);
    // Component a is face-centred along a, cell-centred along the others.
    const __m256i i = a == 0 ? f[0] : c[0], j = a == 1 ? f[1] : c[1], k = a == 2 ? f[2] : c[2];
    const __m256 tx = a == 0 ? tf[0] : tc[0], ty = a == 1 ? tf[1] : tc[1], tz = a == 2 ? tf[2] : tc[2];
    const glm::ivec3 s = g.size();
    alignas(32) std::uint32_t index[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(index),
                       _mm256_add_epi32(i, _mm256_mullo_epi32(_mm256_set1_epi32(s.x),
                                                              _mm256_add_epi32(j, _mm256_mullo_epi32(_mm256_set1_epi32(s.y), k)))));
    v[a] = lerpCells8(cornersOf8(g.data(), Neighbours(g), index), tx, ty, tz);
  }
}

/// trace4() of eight samples i .. i+7 of row (j, k) with first velocities v1, into points
/// 0 .. 7 of `points`.
__attribute__((target("avx2"))) inline void trace8(const MacGrid3& velocity, const __m256* p,
                                                   const __m256* v1, float cells, Trace order,
                                                   glm::vec3 offset, PointSink& points) {
  const __m256 full = _mm256_set1_ps(cells);
  __m256 v[3] = {v1[0], v1[1], v1[2]};
  if (order == Trace::Midpoint) {
    const __m256 half = _mm256_set1_ps(0.5f * cells);
    const __m256 mid[3] = {_mm256_sub_ps(p[0], _mm256_mul_ps(half, v1[0])),
                           _mm256_sub_ps(p[1], _mm256_mul_ps(half, v1[1])),
                           _mm256_sub_ps(p[2], _mm256_mul_ps(half, v1[2]))};
    sampleVelocity8(velocity, mid, v);
  }
  points.set8(0, _mm256_sub_ps(_mm256_sub_ps(p[0], _mm256_mul_ps(full, v[0])), _mm256_set1_ps(offset.x)),
              _mm256_sub_ps(_mm256_sub_ps(p[1], _mm256_mul_ps(full, v[1])), _mm256_set1_ps(offset.y)),
              _mm256_sub_ps(_mm256_sub_ps(p[2], _mm256_mul_ps(full, v[2])), _mm256_set1_ps(offset.z)));
}

/// The traces of eight samples i .. i+7 of row (j, k): back into back[0 .. 7] and, when fore
/// is given, forth into fore[0 .. 7]. x[a], row[a], ty[a], tz[a]: component a's taps on the row.
__attribute__((target("avx2"))) void traceRun8(const MacGrid3& velocity, const XTaps8* x,
                                               const std::ptrdiff_t (*row)[4], const float* ty,
                                               const float* tz, int i, int j, int k,
                                               glm::vec3 offset, float cells, Trace order,
                                               PointSink& back, PointSink* fore) {
  __m256 v1[3];
  for (int a = 0; a < 3; ++a) v1[a] = lerp3x8(x[a], row[a], ty[a], tz[a]);
  const __m256 p[3] = {
      _mm256_add_ps(_mm256_setr_ps(float(i), float(i + 1), float(i + 2), float(i + 3),
                                   float(i + 4), float(i + 5), float(i + 6), float(i + 7)),
                    _mm256_set1_ps(offset.x)),
      _mm256_set1_ps(float(j) + offset.y), _mm256_set1_ps(float(k) + offset.z)};
  trace8(velocity, p, v1, cells, order, offset, back);
  if (fore) trace8(velocity, p, v1, -cells, order, offset, *fore);
}
#endif

/// The scalar form of trace4() for one sample.
inline glm::vec3 traceOne(const MacGrid3& velocity, glm::vec3 p, glm::vec3 v1, float cells,
                          Trace order) {
  return order == Trace::Midpoint ? traceBackFrom(velocity, p, v1, cells) : p - cells * v1;
}

}  // namespace

glm::vec3 traceBack(const MacGrid3& velocity, glm::vec3 p, float cells) {
  return traceBackFrom(velocity, p, sampleVelocity(velocity, p), cells);
}

void BackTracer::prepare(const MacGrid3& velocity, glm::ivec3 size, glm::vec3 offset,
                         float cells, Trace order) {
  mVelocity = &velocity;
  mSize = size;
  mOffset = offset;
  mCells = cells;
  mOrder = order;
  mAvx2 = hasAvx2();
  // The first velocity sample of every trace sits on a sample of the traced grid, where each
  // velocity component is an exact average of 2 or 4 of its faces: its taps along every axis
  // depend on one index only, so they are tabulated once (see Taps) instead of split per sample.
  mTaps.build(velocity, size, offset);
}

void BackTracer::trace(const MacGrid3& velocity, glm::ivec3 size, glm::vec3 offset, float cells,
                       Trace order, const BlockMask* mask, SamplePoints& back,
                       SamplePoints* fore) {
  const std::size_t count = std::size_t(size.x) * size.y * size.z;
  back.resize(size, count);
  if (fore) fore->resize(size, count);
  prepare(velocity, size, offset, cells, order);
  forEachRunOfRows(
      size, mask, [&](int j, int k) { return rowTaps(j, k); },
      [&](const RowTaps& row, int i0, int i1, int j, int k) {
        const std::size_t c = std::size_t(i0) + std::size_t(size.x) * (std::size_t(j) + std::size_t(size.y) * k);
        PointSink backSink = back.sink(c), foreSink = fore ? fore->sink(c) : backSink;
        traceRun(row, i0, i1, j, k, backSink, fore ? &foreSink : nullptr);
      },
      [](int, int, int, int) {});
}

BackTracer::RowTaps BackTracer::rowTaps(int j, int k) const {
  RowTaps r;
  for (int a = 0; a < 3; ++a) {
    const Taps::Tap y = mTaps.at(a, 1, j), z = mTaps.at(a, 2, k);
    const ScalarGrid& comp = mVelocity->component(a);
    const std::ptrdiff_t sy = comp.strideY(), sz = comp.strideZ();
    r.row[a][0] = y.i * sy + z.i * sz;
    r.row[a][1] = r.row[a][0] + sy;
    r.row[a][2] = r.row[a][0] + sz;
    r.row[a][3] = r.row[a][0] + sy + sz;
    r.ty[a] = y.t;
    r.tz[a] = z.t;
  }
  return r;
}

void BackTracer::traceRun(const RowTaps& rowTaps, int i0, int i1, int j, int k, PointSink& back,
                          PointSink* fore) const {
  const MacGrid3& velocity = *mVelocity;
  const glm::vec3 offset = mOffset;
  const float cells = mCells;
  const Trace order = mOrder;
  const float* data[3] = {velocity.u().data(), velocity.v().data(), velocity.w().data()};
  const auto& row = rowTaps.row;
  const float *ty = rowTaps.ty, *tz = rowTaps.tz;
  auto firstVelocity = [&](int i, int a) {
    const Taps::Tap x = mTaps.at(a, 0, i);
    return lerp3(data[a] + x.i, row[a], x.t, ty[a], tz[a]);
  };
  int i = i0;
#if defined(PLUME_TRACE_AVX2)
  // Eight traces at once (AVX2): every full run.
  if (i1 - i0 == 8 && mAvx2) {
    XTaps8 x[3];
    for (int a = 0; a < 3; ++a) {
      const Taps::Tap first = mTaps.at(a, 0, i0), last = mTaps.at(a, 0, i1 - 1);
      // Taps are monotone and irregular only at the sides: equal ends mean a regular run.
      x[a].uniform = last.i == first.i + 7 && last.t == first.t;
      x[a].q = data[a] + first.i;
      x[a].data = data[a];
      x[a].t[0] = first.t;
      if (x[a].uniform) continue;
      for (int m = 0; m < 8; ++m) {
        const Taps::Tap tap = mTaps.at(a, 0, i0 + m);
        x[a].i[m] = tap.i;
        x[a].t[m] = tap.t;
      }
    }
    traceRun8(velocity, x, row, ty, tz, i0, j, k, offset, cells, order, back, fore);
    return;
  }
#endif
#if defined(__SSE4_1__)
  // Four samples at a time; the rest of the run one by one.
  for (; i + 4 <= i1; i += 4) {
    alignas(16) float v1[3][4];
    for (int m = 0; m < 4; ++m)
      for (int a = 0; a < 3; ++a) v1[a][m] = firstVelocity(i + m, a);
    const __m128 p[3] = {
        _mm_add_ps(_mm_setr_ps(float(i), float(i + 1), float(i + 2), float(i + 3)),
                   _mm_set1_ps(offset.x)),
        _mm_set1_ps(float(j) + offset.y), _mm_set1_ps(float(k) + offset.z)};
    const __m128 lanes[3] = {_mm_load_ps(v1[0]), _mm_load_ps(v1[1]), _mm_load_ps(v1[2])};
    trace4(velocity, p, lanes, cells, order, offset, back, i - i0);
    if (fore) trace4(velocity, p, lanes, -cells, order, offset, *fore, i - i0);
  }
#endif
  for (; i < i1; ++i) {
    const glm::vec3 p = glm::vec3(i, j, k) + offset;
    const glm::vec3 v1(firstVelocity(i, 0), firstVelocity(i, 1), firstVelocity(i, 2));
    // Positions are stored in the grid's own index space (cell coordinates - offset).
    back.set(i - i0, traceOne(velocity, p, v1, cells, order) - offset);
    if (fore) fore->set(i - i0, traceOne(velocity, p, v1, -cells, order) - offset);
  }
}

void BackTracer::Taps::build(const MacGrid3& velocity, glm::ivec3 size, glm::vec3 offset) {
  for (int a = 0; a < 3; ++a) {
    const glm::ivec3 n = velocity.component(a).size();
    for (int d = 0; d < 3; ++d) {
      std::vector<Tap>& taps = mTaps[a][d];
      taps.resize(std::size_t(size[d]));
      // Sample m of the traced grid is at m + offset[d] in cell coordinates; component a's
      // samples sit half a cell lower along a.
      const float shift = offset[d] + (d == a ? 0.5f : 0.f);
      for (int m = 0; m < size[d]; ++m) {
        Tap& tap = taps[std::size_t(m)];
        splitCoordinate(float(m) + shift, n[d], tap.i, tap.t);
      }
    }
  }
}

}  // namespace plume
