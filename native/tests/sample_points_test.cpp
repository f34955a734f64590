// Unit tests of split sample points (core/sample_points.h): the kernels that read them (AVX2
// where the CPU has it) must give exactly what the position-based samplers give.
#include "core/rng.h"
#include "core/sample_points.h"
#include "core/sampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace plume {
namespace {

/// A grid of random values and `count` random points in and around it (some outside, some on
/// the sides, where the clamps and the cubic stencil's fallback act).
struct Fixture {
  ScalarGrid grid;
  std::vector<glm::vec3> positions;
  SamplePoints points;
  Fixture(glm::ivec3 size, int count, std::uint64_t seed) : grid(size) {
    Rng rng(seed);
    for (std::size_t n = 0; n < grid.count(); ++n) grid[n] = float(rng.uniform(-1.0, 1.0));
    points.resize(size, std::size_t(count));
    for (int m = 0; m < count; ++m) {
      glm::vec3 p;
      for (int a = 0; a < 3; ++a) p[a] = float(rng.uniform(-1.5, size[a] + 0.5));
      if (m % 5 == 0) p.x = float(size.x - 1);  // exactly on the last sample
      positions.push_back(p);
      points.set(std::size_t(m), p);
    }
  }
};

TEST(SamplePoints, PositionIsTheClampedPosition) {
  const Fixture f({9, 7, 6}, 500, 3);
  for (std::size_t m = 0; m < f.positions.size(); ++m) {
    const glm::vec3 p = glm::clamp(f.positions[m], glm::vec3(0.f), glm::vec3(f.grid.size() - 1));
    ASSERT_EQ(f.points.position(m), p) << m;
  }
}

TEST(SamplePoints, NonFiniteCoordinatesStayInsideTheGrid) {
  // A NaN coordinate (a diverged velocity, a corrupt state) lands on cell 0 instead of the
  // index INT_MIN; infinities clamp onto the sides. The four- and eight-lane forms agree.
  const float nan = std::nanf(""), inf = std::numeric_limits<float>::infinity();
  for (float x : {nan, inf, -inf}) {
    int i = -1;
    float t = -1.f;
    splitCoordinate(x, 9, i, t);
    EXPECT_GE(i, 0) << x;
    EXPECT_LE(i, 7) << x;
    EXPECT_TRUE(t >= 0.f && t <= 1.f) << x;
#if defined(__SSE4_1__)
    __m128i i4;
    __m128 t4;
    splitCoordinate4(_mm_set1_ps(x), 9, i4, t4);
    EXPECT_EQ(_mm_cvtsi128_si32(i4), i) << x;
    EXPECT_EQ(_mm_cvtss_f32(t4), t) << x;
#endif
  }
}

TEST(SamplePoints, KernelsMatchPositionSamplersBitForBit) {
  // Runs of 8 (the AVX2 kernels), of 4 (the cubic kernel) and shorter runs (the scalar tails).
  const Fixture f({13, 10, 9}, 4000, 7);
  for (int count : {8, 5, 4, 1}) {
    for (std::size_t first = 0; first + 8 <= f.positions.size(); first += 8) {
      float linear[8], cubic[8], lo[8], hi[8];
      sampleLinear(f.grid, f.points, first, count, linear);
      sampleMonotonicCubic(f.grid, f.points, first, count, cubic);
      sampleRange(f.grid, f.points, first, count, lo, hi);
      for (int m = 0; m < count; ++m) {
        const glm::vec3 p = f.positions[first + std::size_t(m)];
        float l, h;
        sampleRange(f.grid, p, l, h);
        ASSERT_EQ(linear[m], sampleLinear(f.grid, p)) << first + m;
        ASSERT_EQ(cubic[m], sampleMonotonicCubic(f.grid, p)) << first + m;
        ASSERT_EQ(lo[m], l) << first + m;
        ASSERT_EQ(hi[m], h) << first + m;
      }
    }
  }
}

#if defined(__SSE4_1__)
TEST(SamplePoints, FourLaneSplitMatchesScalarSplit) {
  const Fixture f({11, 8, 7}, 400, 5);
  SamplePoints four;
  four.resize(f.grid.size(), f.positions.size());
  for (std::size_t m = 0; m < f.positions.size(); m += 4) {
    alignas(16) float c[3][4];
    for (int l = 0; l < 4; ++l)
      for (int a = 0; a < 3; ++a) c[a][l] = f.positions[m + std::size_t(l)][a];
    four.sink(m).set4(0, _mm_load_ps(c[0]), _mm_load_ps(c[1]), _mm_load_ps(c[2]));
  }
  for (std::size_t m = 0; m < f.positions.size(); ++m) {
    ASSERT_EQ(four.index()[m], f.points.index()[m]) << m;
    ASSERT_EQ(four.tx()[m], f.points.tx()[m]) << m;
    ASSERT_EQ(four.ty()[m], f.points.ty()[m]) << m;
    ASSERT_EQ(four.tz()[m], f.points.tz()[m]) << m;
  }
}
#endif

#if defined(__x86_64__) && defined(__GNUC__) && !defined(PLUME_NO_AVX2)
/// Points 8m .. 8m+7 of `positions` through set8() (AVX2).
__attribute__((target("avx2"))) void setEight(SamplePoints& points,
                                              const std::vector<glm::vec3>& positions,
                                              std::size_t m) {
  alignas(32) float c[3][8];
  for (int l = 0; l < 8; ++l)
    for (int a = 0; a < 3; ++a) c[a][l] = positions[m + std::size_t(l)][a];
  points.sink(m).set8(0, _mm256_load_ps(c[0]), _mm256_load_ps(c[1]), _mm256_load_ps(c[2]));
}
#endif

TEST(SamplePoints, GhostWeightsOfPointsPastGhostSides) {
  // Past the sides in the mask a point gets ghostWeight() of its unclamped position and kGhost;
  // its group of points is flagged. set(), set4() and set8() must agree bit for bit.
  const glm::ivec3 size(11, 8, 7);
  const std::uint8_t sides = ghostSideBit(0) | ghostSideBit(3) | ghostSideBit(4) | ghostSideBit(5);
  const Fixture f(size, 800, 9);  // positions 1.5 samples past every side and beyond
  SamplePoints one;
  one.setGhostSides(sides);
  one.resize(size, f.positions.size());
  for (std::size_t m = 0; m < f.positions.size(); ++m) one.set(m, f.positions[m]);
  int ghosts = 0;
  for (std::size_t m = 0; m < f.positions.size(); ++m) {
    const float w = ghostWeight(f.positions[m], size, sides);
    const bool flagged = (one.index()[m] & SamplePoints::kGhost) != 0;
    ASSERT_EQ(flagged, w > 0.f) << m;
    ASSERT_EQ(one.index()[m] & ~SamplePoints::kGhost, f.points.index()[m]) << m;
    if (!flagged) continue;
    ++ghosts;
    ASSERT_EQ(one.ghost()[m], w) << m;
    ASSERT_NE(one.index()[m] & SamplePoints::kNearSide, 0u) << m;
    ASSERT_EQ(one.ghostGroups()[m / SamplePoints::kGhostGroup], 1) << m;
  }
  EXPECT_GT(ghosts, 100);
  std::vector<SamplePoints> others;
#if defined(__SSE4_1__)
  others.emplace_back();
  others.back().setGhostSides(sides);
  others.back().resize(size, f.positions.size());
  for (std::size_t m = 0; m < f.positions.size(); m += 4) {
    alignas(16) float c[3][4];
    for (int l = 0; l < 4; ++l)
      for (int a = 0; a < 3; ++a) c[a][l] = f.positions[m + std::size_t(l)][a];
    others.back().sink(m).set4(0, _mm_load_ps(c[0]), _mm_load_ps(c[1]), _mm_load_ps(c[2]));
  }
#endif
#if defined(__x86_64__) && defined(__GNUC__) && !defined(PLUME_NO_AVX2)
  if (hasAvx2()) {
    others.emplace_back();
    others.back().setGhostSides(sides);
    others.back().resize(size, f.positions.size());
    for (std::size_t m = 0; m < f.positions.size(); m += 8) setEight(others.back(), f.positions, m);
  }
#endif
  for (const SamplePoints& p : others)
    for (std::size_t m = 0; m < f.positions.size(); ++m) {
      ASSERT_EQ(p.index()[m], one.index()[m]) << m;
      if (one.index()[m] & SamplePoints::kGhost) ASSERT_EQ(p.ghost()[m], one.ghost()[m]) << m;
      ASSERT_EQ(p.ghostGroups()[m / SamplePoints::kGhostGroup],
                one.ghostGroups()[m / SamplePoints::kGhostGroup]) << m;
    }
}

}  // namespace
}  // namespace plume
