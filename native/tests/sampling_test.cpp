// Unit tests of core sampling (trilinear, monotonic cubic of Fedkiw 2001).
#include "core/rng.h"
#include "core/sampling.h"

#include <gtest/gtest.h>

namespace plume {
namespace {

TEST(Sampling, LinearIsExactForLinearFields) {
  ScalarGrid g({6, 5, 4});
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 6; ++i) g(i, j, k) = 1.f + 2.f * i - 3.f * j + 0.5f * k;
  const glm::vec3 p(2.3f, 1.7f, 2.9f);
  EXPECT_NEAR(sampleLinear(g, p), 1.f + 2.f * p.x - 3.f * p.y + 0.5f * p.z, 1e-5f);
}

TEST(Sampling, MonotonicCubicIsExactForCubicsAwayFromClamping) {
  // Hermite with central-difference slopes reproduces quadratics exactly when not limited.
  ScalarGrid g({8, 1, 1});
  for (int i = 0; i < 8; ++i) g(i, 0, 0) = float(i * i);
  EXPECT_NEAR(sampleMonotonicCubic(g, {3.5f, 0.f, 0.f}), 3.5f * 3.5f, 1e-4f);
}

TEST(Sampling, MonotonicCubicMakesNoNewExtrema) {
  // Sharp steps are where an unlimited cubic overshoots; the limited one must stay in range.
  Rng rng(7);
  ScalarGrid g({9, 9, 9});
  for (std::size_t n = 0; n < g.count(); ++n) g[n] = rng.uniform() < 0.5 ? 0.f : 1.f;
  for (int s = 0; s < 20000; ++s) {
    const glm::vec3 p(rng.uniform(0, 8), rng.uniform(0, 8), rng.uniform(0, 8));
    const float v = sampleMonotonicCubic(g, p);
    float lo, hi;
    sampleRange(g, p, lo, hi);
    ASSERT_GE(v, lo - 1e-6f);
    ASSERT_LE(v, hi + 1e-6f);
  }
}

TEST(Sampling, MonotonicCubicMatchesAxisByAxisDefinition) {
  // The vectorised 3-D sampler (in place inside the grid, from a clamped copy near the sides)
  // must give exactly the per-axis composition of monotonicCubic1D: x, then y, then z.
  Rng rng(11);
  ScalarGrid g({7, 6, 5});
  for (std::size_t n = 0; n < g.count(); ++n) g[n] = float(rng.uniform(-2, 2));
  for (int s = 0; s < 5000; ++s) {
    const glm::vec3 p(rng.uniform(-1, 7), rng.uniform(-1, 6), rng.uniform(-1, 5));
    const glm::ivec3 n = g.size();
    const glm::vec3 c = glm::clamp(p, glm::vec3(0.f), glm::vec3(n - 1));
    const glm::ivec3 b = glm::min(glm::ivec3(c), n - 2);
    const glm::vec3 t = c - glm::vec3(b);
    float zs[4];
    for (int z = 0; z < 4; ++z) {
      float ys[4];
      for (int y = 0; y < 4; ++y) {
        auto at = [&](int x) { return g.clampedAt(b.x - 1 + x, b.y - 1 + y, b.z - 1 + z); };
        ys[y] = monotonicCubic1D(at(0), at(1), at(2), at(3), t.x);
      }
      zs[z] = monotonicCubic1D(ys[0], ys[1], ys[2], ys[3], t.y);
    }
    ASSERT_EQ(sampleMonotonicCubic(g, p), monotonicCubic1D(zs[0], zs[1], zs[2], zs[3], t.z));
  }
}

TEST(Sampling, MonotonicCubic4MatchesSingleSamplesBitForBit) {
  // The four-at-once kernel (AVX2 or SSE) must give exactly sampleMonotonicCubic, also for
  // points whose stencil leaves the grid and points outside it.
  Rng rng(11);
  ScalarGrid g({13, 10, 9});
  for (std::size_t n = 0; n < g.count(); ++n) g[n] = rng.uniform(-1.f, 1.f);
  for (int s = 0; s < 5000; ++s) {
    glm::vec3 p[4];
    for (glm::vec3& q : p) q = {rng.uniform(-1.f, 13.f), rng.uniform(-1.f, 10.f), rng.uniform(-1.f, 9.f)};
    float out[4];
    sampleMonotonicCubic4(g, p, out);
    for (int m = 0; m < 4; ++m) ASSERT_EQ(out[m], sampleMonotonicCubic(g, p[m]));
  }
}

TEST(Sampling, MonotonicCubic1DIsMonotoneOnMonotoneData) {
  // Data rising steeply then flat: the interpolant between each pair must not go back.
  const float f[6] = {0.f, 0.1f, 5.f, 5.1f, 5.1f, 9.f};
  for (int s = 1; s < 4; ++s) {
    float prev = f[s];
    for (int t = 1; t <= 50; ++t) {
      const float v = monotonicCubic1D(f[s - 1], f[s], f[s + 1], f[s + 2], t / 50.f);
      EXPECT_GE(v, prev - 1e-6f);
      prev = v;
    }
  }
}

}  // namespace
}  // namespace plume
