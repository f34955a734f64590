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
