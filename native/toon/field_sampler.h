#pragma once
/// \file field_sampler.h
/// The trilinear samples a toon particle takes (cartoon_smoke.txt §2.1: "position, velocity, and
/// density are linearly interpolated from the simulation grid"), four particles at a time: the
/// clamped split of each coordinate is computed once per position and shared by every field (the
/// cell-centred density and temperature, and the three staggered velocity components), and the
/// interpolation runs on four SSE lanes. Each lane's value is the one sampleLinear /
/// sampleVelocity (core/sampling.h) return, bit for bit: same clamping, same operations in the
/// same order.

#include "core/grid3.h"
#include "core/mac_grid3.h"
#include "core/sample_points.h"

#include <smmintrin.h>

namespace plume {

/// Lower sample index and fraction of four coordinates clamped to [0, n-1]
/// (core/sample_points.h splitCoordinate4, the split of every Plume sample).
struct AxisSplit4 {
  __m128i i;
  __m128 t;
  AxisSplit4() = default;
  AxisSplit4(__m128 x, int n) { splitCoordinate4(x, n, i, t); }
};

/// The splits of four positions c[0..3] in cell coordinates (cell (i,j,k)'s centre at (i,j,k)) on
/// a grid of n cells: centred for the cell grids, staggered (c + ½ on n + 1 faces) for the faces.
struct PositionSplits4 {
  AxisSplit4 centred[3];
  AxisSplit4 staggered[3];
  PositionSplits4(glm::ivec3 n, const glm::vec3* c) {
    for (int a = 0; a < 3; ++a) {
      const __m128 x = _mm_setr_ps(c[0][a], c[1][a], c[2][a], c[3][a]);
      centred[a] = AxisSplit4(x, n[a]);
      staggered[a] = AxisSplit4(_mm_add_ps(x, _mm_set1_ps(0.5f)), n[a] + 1);
    }
  }
};

/// Trilinear samples of g at four stencils (x, y, z): sampleLinear's arithmetic on each lane.
inline __m128 trilinear4(const ScalarGrid& g, const AxisSplit4& x, const AxisSplit4& y,
                         const AxisSplit4& z) {
  const glm::ivec3 n = g.size();
  const std::ptrdiff_t dx = n.x > 1 ? 1 : 0;
  const std::ptrdiff_t dy = n.y > 1 ? g.strideY() : 0;
  const std::ptrdiff_t dz = n.z > 1 ? g.strideZ() : 0;
  alignas(16) int ix[4], iy[4], iz[4];
  _mm_store_si128(reinterpret_cast<__m128i*>(ix), x.i);
  _mm_store_si128(reinterpret_cast<__m128i*>(iy), y.i);
  _mm_store_si128(reinterpret_cast<__m128i*>(iz), z.i);
  // f[corner][lane], corner bits: x, y, z.
  alignas(16) float f[8][4];
  for (int m = 0; m < 4; ++m) {
    const float* q = g.data() + g.index(ix[m], iy[m], iz[m]);
    f[0][m] = q[0];
    f[1][m] = q[dx];
    f[2][m] = q[dy];
    f[3][m] = q[dy + dx];
    f[4][m] = q[dz];
    f[5][m] = q[dz + dx];
    f[6][m] = q[dz + dy];
    f[7][m] = q[dz + dy + dx];
  }
  auto lerp = [](__m128 a, __m128 b, __m128 t) { return _mm_add_ps(a, _mm_mul_ps(t, _mm_sub_ps(b, a))); };
  auto at = [&](int c) { return _mm_load_ps(f[c]); };
  const __m128 c00 = lerp(at(0), at(1), x.t), c10 = lerp(at(2), at(3), x.t);
  const __m128 c01 = lerp(at(4), at(5), x.t), c11 = lerp(at(6), at(7), x.t);
  return lerp(lerp(c00, c10, y.t), lerp(c01, c11, y.t), z.t);
}

/// A cell-centred grid at the four positions, into out[0..3].
inline void sampleCentred4(const ScalarGrid& g, const PositionSplits4& s, float* out) {
  _mm_storeu_ps(out, trilinear4(g, s.centred[0], s.centred[1], s.centred[2]));
}

/// The face velocity at the four positions (sampleVelocity's values), into out[0..3].
inline void sampleFaces4(const MacGrid3& v, const PositionSplits4& s, glm::vec3* out) {
  alignas(16) float c[3][4];
  _mm_store_ps(c[0], trilinear4(v.u(), s.staggered[0], s.centred[1], s.centred[2]));
  _mm_store_ps(c[1], trilinear4(v.v(), s.centred[0], s.staggered[1], s.centred[2]));
  _mm_store_ps(c[2], trilinear4(v.w(), s.centred[0], s.centred[1], s.staggered[2]));
  for (int m = 0; m < 4; ++m) out[m] = glm::vec3(c[0][m], c[1][m], c[2][m]);
}

}  // namespace plume
