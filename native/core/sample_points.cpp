#include "core/sample_points.h"

#include "core/huge_pages.h"
#include "core/linear_cells.h"

namespace plume {
namespace {

#if defined(PLUME_LINEAR_CELLS_AVX2)
#define PLUME_GATHER_DISPATCH 1

__attribute__((target("avx2"))) void linear8(const float* data, const Neighbours& d,
                                             const std::uint32_t* index, const float* tx,
                                             const float* ty, const float* tz, float* out) {
  _mm256_storeu_ps(out, lerpCells8(cornersOf8(data, d, index), tx, ty, tz));
}

__attribute__((target("avx2"))) void range8(const float* data, const Neighbours& d,
                                            const std::uint32_t* index, float* lo, float* hi) {
  __m256 l, h;
  rangeCells8(cornersOf8(data, d, index), l, h);
  _mm256_storeu_ps(lo, l);
  _mm256_storeu_ps(hi, h);
}

const bool kHasAvx2 = hasAvx2();

#endif

}  // namespace

void SamplePoints::reserve(std::size_t count) {
  reserveHugePages(mIndex, count);
  for (std::vector<float>& t : mT) reserveHugePages(t, count);
  // Ghost weights: reserved only (untouched pages cost nothing where no side is a ghost side).
  reserveHugePages(mGhost, count);
  mGhostGroups.reserve(count / SamplePoints::kGhostGroup + 1);
}

void SamplePoints::resize(glm::ivec3 gridSize, std::size_t count) {
  mGridSize = gridSize;
  mIndex.resize(count);
  for (std::vector<float>& t : mT) t.resize(count);
  if (mGhostSides == 0) return;
  mGhost.resize(count);
  mGhostGroups.assign((count + kGhostGroup - 1) / kGhostGroup, 0);
}

void PointSink::set(int m, glm::vec3 p) {
  const glm::ivec3 s = mGridSize;
  int c[3];
  for (int a = 0; a < 3; ++a) splitCoordinate(p[a], s[a], c[a], mT[a][m]);
  const bool inside =
      c[0] >= 1 && c[1] >= 1 && c[2] >= 1 && c[0] + 2 < s.x && c[1] + 2 < s.y && c[2] + 2 < s.z;
  mIndex[m] = std::uint32_t(c[0] + s.x * (c[1] + s.y * c[2])) |
              (inside ? 0u : SamplePoints::kNearSide);
  // A point past a side is clamped onto it, so only points near a side can have a ghost weight.
  if (mGhostSides == 0 || inside) return;
  const float w = ghostWeight(p, s, mGhostSides);
  if (!(w > 0.f)) return;
  mGhost[m] = w;
  mIndex[m] |= SamplePoints::kGhost;
  mGroups[(mFirst + std::size_t(m)) / SamplePoints::kGhostGroup] = 1;
}

#if defined(__SSE4_1__)
void PointSink::set4(int m, __m128 x, __m128 y, __m128 z) {
  // Lane by lane: set4 only serves CPUs without AVX2 and the odd tail of a run.
  alignas(16) float c[3][4];
  _mm_store_ps(c[0], x);
  _mm_store_ps(c[1], y);
  _mm_store_ps(c[2], z);
  for (int l = 0; l < 4; ++l) set(m + l, {c[0][l], c[1][l], c[2][l]});
}
#endif

#if defined(PLUME_GATHER_DISPATCH)
__attribute__((target("avx2"))) __m256i PointSink::ghost8(int m, const __m256* pos) {
  const __m256i none = _mm256_setzero_si256();
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.f);
  __m256 outside = zero;
  for (int a = 0; a < 3; ++a) {
    const __m256 last = _mm256_set1_ps(float(mGridSize[a] - 1));
    if (mGhostSides & ghostSideBit(2 * a))
      outside = _mm256_or_ps(outside, _mm256_cmp_ps(pos[a], zero, _CMP_LT_OQ));
    if (mGhostSides & ghostSideBit(2 * a + 1))
      outside = _mm256_or_ps(outside, _mm256_cmp_ps(pos[a], last, _CMP_GT_OQ));
  }
  if (_mm256_testz_ps(outside, outside)) return none;  // most points near a side
  __m256 keep = one;
  for (int a = 0; a < 3; ++a) {
    // ghostWeight()'s operations on eight lanes (adding the 0 of a non-ghost side is exact).
    const __m256 below = _mm256_max_ps(_mm256_sub_ps(zero, pos[a]), zero);
    const __m256 last = _mm256_set1_ps(float(mGridSize[a] - 1));
    const __m256 past = _mm256_max_ps(_mm256_sub_ps(pos[a], last), zero);
    __m256 d = zero;
    if (mGhostSides & ghostSideBit(2 * a)) d = _mm256_add_ps(d, below);
    if (mGhostSides & ghostSideBit(2 * a + 1)) d = _mm256_add_ps(d, past);
    keep = _mm256_mul_ps(keep, _mm256_sub_ps(one, _mm256_min_ps(d, one)));
  }
  const __m256 w = _mm256_sub_ps(one, keep);
  const __m256 has = _mm256_cmp_ps(w, zero, _CMP_GT_OQ);
  _mm256_storeu_ps(mGhost + m, w);
  // The eight points lie in at most two groups: points 0 .. split-1 in the first.
  const unsigned lanes = unsigned(_mm256_movemask_ps(has));
  const std::size_t first = mFirst + std::size_t(m), g = first / SamplePoints::kGhostGroup;
  const unsigned split = unsigned(SamplePoints::kGhostGroup - first % SamplePoints::kGhostGroup);
  if (lanes & ((1u << split) - 1u)) mGroups[g] = 1;
  if (split < 8 && (lanes >> split)) mGroups[g + 1] = 1;
  return _mm256_and_si256(_mm256_castps_si256(has), _mm256_set1_epi32(int(SamplePoints::kGhost)));
}

__attribute__((target("avx2"))) void PointSink::set8(int m, __m256 x, __m256 y, __m256 z) {
  const __m256 pos[3] = {x, y, z};
  __m256i c[3], inside = _mm256_set1_epi32(-1);
  for (int a = 0; a < 3; ++a) {
    __m256 t;
    splitCoordinate8(pos[a], mGridSize[a], c[a], t);
    _mm256_storeu_ps(mT[a] + m, t);
    // 1 <= c and c + 2 < size
    inside = _mm256_and_si256(inside, _mm256_cmpgt_epi32(c[a], _mm256_setzero_si256()));
    inside = _mm256_and_si256(inside, _mm256_cmpgt_epi32(_mm256_set1_epi32(mGridSize[a] - 2), c[a]));
  }
  const __m256i index = _mm256_add_epi32(
      c[0], _mm256_mullo_epi32(
                _mm256_set1_epi32(mGridSize.x),
                _mm256_add_epi32(c[1], _mm256_mullo_epi32(_mm256_set1_epi32(mGridSize.y), c[2]))));
  const __m256i near = _mm256_andnot_si256(inside, _mm256_set1_epi32(int(SamplePoints::kNearSide)));
  __m256i flags = near;
  // Only a point clamped onto a ghost side has a ghost weight, and such a point is near a side.
  if (mGhostSides != 0 && !_mm256_testz_si256(near, near))
    flags = _mm256_or_si256(flags, ghost8(m, pos));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(mIndex + m), _mm256_or_si256(index, flags));
}
#endif

glm::vec3 SamplePoints::position(std::size_t n) const {
  // i + t is exact: t = x - i was computed exactly (Sterbenz), so the sum gives x back.
  const std::uint32_t c = mIndex[n] & kIndexMask;
  const std::uint32_t nx = std::uint32_t(mGridSize.x), ny = std::uint32_t(mGridSize.y);
  const float i = float(c % nx), j = float((c / nx) % ny), k = float(c / (nx * ny));
  return {i + mT[0][n], j + mT[1][n], k + mT[2][n]};
}

void sampleLinear(const ScalarGrid& g, const SamplePoints& points, std::size_t first, int count,
                  float* out) {
  const Neighbours d(g);
  const std::uint32_t* index = points.index() + first;
  const float *tx = points.tx() + first, *ty = points.ty() + first, *tz = points.tz() + first;
  int m = 0;
#if defined(PLUME_GATHER_DISPATCH)
  if (kHasAvx2)
    for (; m + 8 <= count; m += 8)
      linear8(g.data(), d, index + m, tx + m, ty + m, tz + m, out + m);
#endif
  for (; m < count; ++m)
    out[m] = lerpCell(g.data() + (index[m] & SamplePoints::kIndexMask), d, tx[m], ty[m], tz[m]);
}

void sampleRange(const ScalarGrid& g, const SamplePoints& points, std::size_t first, int count,
                 float* lo, float* hi) {
  const Neighbours d(g);
  const std::uint32_t* index = points.index() + first;
  int m = 0;
#if defined(PLUME_GATHER_DISPATCH)
  if (kHasAvx2)
    for (; m + 8 <= count; m += 8) range8(g.data(), d, index + m, lo + m, hi + m);
#endif
  for (; m < count; ++m)
    rangeCell(g.data() + (index[m] & SamplePoints::kIndexMask), d, lo[m], hi[m]);
}

}  // namespace plume
