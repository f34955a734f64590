// The break point of §4.3 ([Structural Flames]): over many separations the split height h has
// the prose's normal distribution, mean H_p + (H_i − H_p)/2 and standard deviation (H_i − H_p)/4,
// as clamped by breakaway.cpp to [max(H_p, H_i/100), H_i] (= μ ± 2σ here).
#include "flames/breakaway.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace plume {
namespace {

TEST(FlameBreakaway, SplitHeightHasTheMeanAndDeviationOfSection43) {
  const FlameHeights heights{/*persistent=*/0.08, /*intermittent=*/0.16, /*max=*/0.35};
  const double mu = 0.08 + 0.5 * (0.16 - 0.08), sigma = 0.25 * (0.16 - 0.08);
  const int count = 200000;
  Rng rng(11);
  double budget = 0.0;
  std::vector<double> h;
  h.reserve(count);
  for (int i = 0; i < count; ++i) {
    // A flame of 0.3 m (past H_i, below H_max: a statistical, not a forced, break) over a step
    // far longer than 1/f: the Poisson budget is spent every step, so every step separates.
    const BreakawayDecision d = testBreakaway(/*length=*/0.3, heights, /*frequency=*/1.0, /*dt=*/1e6, budget, rng);
    ASSERT_TRUE(d.split && d.eligible && !d.forced);
    h.push_back(d.height);
  }
  double sum = 0.0, sum2 = 0.0;
  int atLow = 0, atHigh = 0;
  for (double v : h) {
    sum += v;
    ASSERT_GE(v, heights.persistent);
    ASSERT_LE(v, heights.intermittent);
    atLow += v == heights.persistent;
    atHigh += v == heights.intermittent;
  }
  const double mean = sum / count;
  for (double v : h) sum2 += (v - mean) * (v - mean);
  const double sd = std::sqrt(sum2 / (count - 1));

  // The clamp at μ ± 2σ keeps the mean (symmetric) and shrinks the deviation: for Z ~ N(0, 1)
  // clamped to [−2, 2], Var = P(|Z| < 2) − 2·2 φ(2) + 2·2² P(Z > 2) = 0.9205, σ_c = 0.9594 σ.
  const double phi2 = std::exp(-2.0) / std::sqrt(2.0 * 3.14159265358979323846);
  const double tail = 0.5 * std::erfc(2.0 / std::sqrt(2.0));  // P(Z > 2)
  const double clampedSigma = sigma * std::sqrt((1.0 - 2.0 * tail) - 4.0 * phi2 + 8.0 * tail);
  // Tolerances: 4 standard errors of the sample count. SE(mean) = σ_c/√N; SE(sd) = σ_c/√(2N) for
  // a normal sample (kurtosis 3; the clamped one has less, so this is conservative).
  const double seMean = clampedSigma / std::sqrt(double(count));
  const double seSd = clampedSigma / std::sqrt(2.0 * count);
  std::printf("split height over %d separations: mean %.6f m (μ %.6f), sd %.6f m (σ_c %.6f, σ %.6f)\n", count,
              mean, mu, sd, clampedSigma, sigma);
  EXPECT_NEAR(mean, mu, 4.0 * seMean);
  EXPECT_NEAR(sd, clampedSigma, 4.0 * seSd);

  // σ itself, unaffected by the clamp: the quartiles (±0.6745 σ) lie well inside ±2σ, so
  // IQR / 1.34898 estimates σ. Its SE is ≈ 1.166 σ/√N (the IQR estimator's 37% efficiency).
  std::sort(h.begin(), h.end());
  const double iqrSigma = (h[std::size_t(0.75 * count)] - h[std::size_t(0.25 * count)]) / 1.3489795;
  std::printf("σ from the interquartile range: %.6f m (σ %.6f)\n", iqrSigma, sigma);
  EXPECT_NEAR(iqrSigma, sigma, 4.0 * 1.166 * sigma / std::sqrt(double(count)));
  // Each clamp holds the tail beyond 2σ: P(Z > 2) = 2.275%, binomial SE.
  const double seTail = std::sqrt(tail * (1.0 - tail) / count);
  EXPECT_NEAR(double(atLow) / count, tail, 4.0 * seTail);
  EXPECT_NEAR(double(atHigh) / count, tail, 4.0 * seTail);
}

}  // namespace
}  // namespace plume
