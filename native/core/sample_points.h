#pragma once
/// \file sample_points.h
/// Points at which several grids of one shape are sampled (the back-traces of semi-Lagrangian
/// advection, Stam 1999 §3.2), kept as what trilinear and monotonic cubic sampling read of a
/// position: the cell it falls in and the fractions along each axis. Splitting a position costs
/// about as much as the trilinear lerps; split once, the weights serve every field and every
/// pass of BFECC / MacCormack. Structure of arrays: eight consecutive points load as one AVX2
/// register per coordinate, and the trilinear kernels gather their corners eight at a time.

#include "core/cpu_features.h"
#include "core/grid3.h"

#include <cstdint>
#include <vector>

#if defined(__SSE4_1__) || defined(__x86_64__)
#include <immintrin.h>
#endif

namespace plume {

/// Cell i and fraction t of coordinate x on an axis of n samples: x clamped into [0, n-1], the
/// last cell taken for x = n-1. Every trilinear and cubic sample of Plume splits this way.
inline void splitCoordinate(float x, int n, int& i, float& t) {
  const float hi = float(n - 1);
  // max(x, 0) then min(x, hi) as SSE's maxps/minps select (a > b ? a : b, a < b ? a : b): a NaN
  // coordinate lands on 0 instead of becoming the index INT_MIN.
  x = x > 0.f ? x : 0.f;
  x = x < hi ? x : hi;
  i = int(x);
  if (i >= n - 1) i = n > 1 ? n - 2 : 0;
  t = x - float(i);
}

#if defined(__SSE4_1__)
/// splitCoordinate() on four lanes, with the same operations (the clamps select like the scalar
/// form; lanes differ at most in the sign of a zero fraction, which no sample depends on).
inline void splitCoordinate4(__m128 x, int n, __m128i& i, __m128& t) {
  const __m128 zero = _mm_setzero_ps(), hi = _mm_set1_ps(float(n - 1));
  x = _mm_min_ps(_mm_max_ps(x, zero), hi);  // NaN -> 0, as the scalar form
  i = _mm_cvttps_epi32(x);
  const __m128i last = _mm_cmpgt_epi32(i, _mm_set1_epi32(n - 2));  // i >= n - 1
  i = _mm_blendv_epi8(i, _mm_set1_epi32(n > 1 ? n - 2 : 0), last);
  t = _mm_sub_ps(x, _mm_cvtepi32_ps(i));
}
#endif

#if defined(__x86_64__) && defined(__GNUC__) && !defined(PLUME_NO_AVX2)
/// splitCoordinate4() on eight lanes (AVX2; call only when hasAvx2()).
__attribute__((target("avx2"))) inline void splitCoordinate8(__m256 x, int n, __m256i& i,
                                                             __m256& t) {
  const __m256 zero = _mm256_setzero_ps(), hi = _mm256_set1_ps(float(n - 1));
  x = _mm256_min_ps(_mm256_max_ps(x, zero), hi);  // NaN -> 0, as the scalar form
  i = _mm256_cvttps_epi32(x);
  const __m256i last = _mm256_cmpgt_epi32(i, _mm256_set1_epi32(n - 2));  // i >= n - 1
  i = _mm256_blendv_epi8(i, _mm256_set1_epi32(n > 1 ? n - 2 : 0), last);
  t = _mm256_sub_ps(x, _mm256_cvtepi32_ps(i));
}
#endif

/// Bit of side s (-x, +x, -y, +y, -z, +z, as plume::Side) in a mask of ghost sides.
constexpr std::uint8_t ghostSideBit(int side) { return std::uint8_t(1u << side); }

/// Share of a ghost layer in the trilinear sample at p (index space of a grid of `size`): past
/// the last sample on a side in `sides`, the grid continues with one more layer of a constant
/// value (the ambient air beyond an open side of the domain), so a position that far or further
/// out reads it alone. Per axis w_a = min(1, distance past the last sample), and the ghost's
/// share is 1 - Π_a (1 - w_a), exactly what a trilinear sample of the padded grid gives it.
inline float ghostWeight(glm::vec3 p, glm::ivec3 size, std::uint8_t sides) {
  float keep = 1.f;
  for (int a = 0; a < 3; ++a) {
    float d = 0.f;
    if (sides & ghostSideBit(2 * a)) d += p[a] < 0.f ? -p[a] : 0.f;
    const float past = p[a] - float(size[a] - 1);
    if (sides & ghostSideBit(2 * a + 1)) d += past > 0.f ? past : 0.f;
    keep *= 1.f - (d < 1.f ? d : 1.f);
  }
  return 1.f - keep;
}

/// Where split points are written: set() and friends split a position and store it as point m
/// (clamped into the grid, cell and fractions exactly as sampleLinear() and
/// sampleMonotonicCubic() split it, core/sampling.cpp), and, with ghost sides, the ghost weight
/// (ghostWeight() of the unclamped position) of the points that have one.
class PointSink {
 public:
  /// With ghost sides: `ghost` is where the ghost weight of point 0 goes, `groups` the flags of
  /// SamplePoints::ghostGroups(), `first` the number of point 0 among them.
  PointSink(glm::ivec3 gridSize, std::uint32_t* index, float* tx, float* ty, float* tz,
            std::uint8_t ghostSides = 0, float* ghost = nullptr, std::uint8_t* groups = nullptr,
            std::size_t first = 0)
      : mGridSize(gridSize), mIndex(index), mT{tx, ty, tz}, mGhostSides(ghostSides),
        mGhost(ghost), mGroups(groups), mFirst(first) {}
  void set(int m, glm::vec3 p);
#if defined(__SSE4_1__)
  /// set() of points m .. m+3 at the lanes of x, y, z.
  void set4(int m, __m128 x, __m128 y, __m128 z);
#endif
#if defined(__x86_64__) && defined(__GNUC__) && !defined(PLUME_NO_AVX2)
  /// set() of points m .. m+7 (AVX2; call only when hasAvx2()).
  __attribute__((target("avx2"))) void set8(int m, __m256 x, __m256 y, __m256 z);
#endif

 private:
  glm::ivec3 mGridSize;
  std::uint32_t* mIndex;
  float* mT[3];
#if defined(__x86_64__) && defined(__GNUC__) && !defined(PLUME_NO_AVX2)
  /// set8()'s ghost weights of points m .. m+7 at pos (unclamped, some of them near a side);
  /// returns their kGhost flags.
  __attribute__((target("avx2"))) __m256i ghost8(int m, const __m256* pos);
#endif

  std::uint8_t mGhostSides;
  float* mGhost;
  std::uint8_t* mGroups;
  std::size_t mFirst;
};

/// Split positions in the index space of grids of one size (sample (i,j,k) at p = (i,j,k)).
class SamplePoints {
 public:
  /// Flag in index(): the point's 4×4×4 monotonic cubic stencil (i-1 .. i+2) leaves the grid.
  static constexpr std::uint32_t kNearSide = 1u << 31;
  /// Flag in index(), with ghost sides only: the point has a ghost weight > 0 (in ghost()). Such
  /// a point is clamped onto a side, so it has kNearSide too.
  static constexpr std::uint32_t kGhost = 1u << 30;
  /// The index without the flags (grids hold fewer than 2^30 samples: SmokeParams::validate()).
  static constexpr std::uint32_t kIndexMask = kGhost - 1u;

  /// Allocates room for `count` points; resize() within it never allocates.
  void reserve(std::size_t count);
  /// `count` points (values unset) in grids of `gridSize` samples; clears the ghost groups.
  void resize(glm::ivec3 gridSize, std::size_t count);
  /// Sides (ghostSideBit() mask) past which the grid continues with a constant ghost layer:
  /// points written after the next resize() get their ghostWeight(). 0 (the default): none.
  void setGhostSides(std::uint8_t sides) { mGhostSides = sides; }
  std::uint8_t ghostSides() const { return mGhostSides; }

  /// Writes points first, first+1, ... (PointSink's m counts from `first`).
  PointSink sink(std::size_t first) {
    if (mGhostSides == 0)
      return {mGridSize, mIndex.data() + first, mT[0].data() + first, mT[1].data() + first,
              mT[2].data() + first};
    return {mGridSize, mIndex.data() + first, mT[0].data() + first, mT[1].data() + first,
            mT[2].data() + first, mGhostSides, mGhost.data() + first, mGhostGroups.data(), first};
  }
  /// Stores point n at p.
  void set(std::size_t n, glm::vec3 p) { sink(n).set(0, p); }
  /// The clamped position of point n: cell + fraction per axis, exactly what was split.
  glm::vec3 position(std::size_t n) const;

  glm::ivec3 gridSize() const { return mGridSize; }
  std::size_t count() const { return mIndex.size(); }
  /// Linear index of the lower corner of point n's trilinear cell, with kNearSide.
  const std::uint32_t* index() const { return mIndex.data(); }
  /// Fractions in [0, 1] along x, y, z.
  const float* tx() const { return mT[0].data(); }
  const float* ty() const { return mT[1].data(); }
  const float* tz() const { return mT[2].data(); }
  /// With ghost sides: the ghost weight of point n where index() has kGhost (elsewhere the
  /// weight is 0 and this holds anything).
  const float* ghost() const { return mGhost.data(); }
  /// Points come in groups of kGhostGroup (n / kGhostGroup); with ghost sides, the flag of a
  /// group is set when one of its points written since resize() got a ghost weight > 0, so
  /// that the few such points are found without reading the others.
  static constexpr std::size_t kGhostGroup = 8;
  const std::uint8_t* ghostGroups() const { return mGhostGroups.data(); }

 private:
  glm::ivec3 mGridSize{0};
  std::vector<std::uint32_t> mIndex;
  std::vector<float> mT[3];
  std::uint8_t mGhostSides = 0;
  std::vector<float> mGhost;               ///< sized only with ghost sides
  std::vector<std::uint8_t> mGhostGroups;  ///< one flag per kGhostGroup points
};

/// Trilinear samples of `grid` at points first .. first+count-1 into out[0 .. count-1]: the
/// values sampleLinear() gives at their positions, bit for bit (AVX2 where the CPU has it).
/// grid must have the points' grid size.
void sampleLinear(const ScalarGrid& grid, const SamplePoints& points, std::size_t first,
                  int count, float* out);

/// sampleRange() of `grid` at points first .. first+count-1: smallest and largest of the 8
/// samples of each trilinear cell (the clamp limiter of BFECC and MacCormack).
void sampleRange(const ScalarGrid& grid, const SamplePoints& points, std::size_t first,
                 int count, float* lo, float* hi);

/// Monotonic cubic samples (Fedkiw 2001 eq. 12-13) at points first .. first+count-1, bit for
/// bit sampleMonotonicCubic() at their positions (defined in core/sampling.cpp, next to the
/// cubic kernels it shares).
void sampleMonotonicCubic(const ScalarGrid& grid, const SamplePoints& points, std::size_t first,
                          int count, float* out);

}  // namespace plume
