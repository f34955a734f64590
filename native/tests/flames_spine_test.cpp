// Structural flames, the pieces ([Structural Flames] §4.1–4.3, §6.1): spines (interpolation,
// arc-length re-sampling), wind fields, obstacle distance fields, the breakaway draws and the
// settings' checks.
#include "flames/breakaway.h"
#include "flames/flame_params.h"
#include "flames/obstacle_sdf.h"
#include "flames/spine.h"
#include "flames/wind.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace plume {
namespace {

/// Irregularly spaced points on a bent curve (a flame leaning and curling), about 0.5 m long.
std::vector<SpinePoint> bentPoints() {
  const double t[] = {0.0, 0.05, 0.07, 0.2, 0.38, 0.41, 0.7, 1.0};
  std::vector<SpinePoint> pts;
  for (double u : t) {
    SpinePoint p;
    p.x = glm::dvec3(0.15 * std::sin(3.0 * u), 0.05 * u * u, 0.5 * u);
    p.age = u;
    p.v = glm::dvec3(u, 0.0, 1.0);
    pts.push_back(p);
  }
  return pts;
}

/// Cumulative length of a dense polyline of the curve (an independent arc-length measure).
struct DenseCurve {
  std::vector<glm::dvec3> x;
  std::vector<double> s;
  DenseCurve(const Spine& spine, int samples) {
    for (int i = 0; i <= samples; ++i) {
      x.push_back(spine.evaluate(spine.parameterEnd() * i / samples));
      s.push_back(i == 0 ? 0.0 : s.back() + glm::length(x.back() - x[x.size() - 2]));
    }
  }
  /// Arc length at the dense sample nearest to p, and that distance.
  double locate(const glm::dvec3& p, double& distance) const {
    std::size_t best = 0;
    for (std::size_t i = 1; i < x.size(); ++i)
      if (glm::length(x[i] - p) < glm::length(x[best] - p)) best = i;
    distance = glm::length(x[best] - p);
    return s[best];
  }
};

TEST(FlameSpine, PassesThroughItsPoints) {
  const std::vector<SpinePoint> pts = bentPoints();
  const Spine spine = Spine::fit(pts);
  ASSERT_EQ(spine.knots().size(), pts.size());
  // At u_k the span's cubic is P_k + 0 (or P_{k+1} at the far end): only rounding, ~1e-16 m.
  for (std::size_t k = 0; k < pts.size(); ++k)
    EXPECT_LT(glm::length(spine.evaluate(spine.knots()[k]) - pts[k].x), 1e-12) << "point " << k;
  // C² where spans meet: left and right derivatives agree (one cubic per span, natural spline).
  for (std::size_t k = 1; k + 1 < pts.size(); ++k) {
    const double u = spine.knots()[k];
    EXPECT_LT(glm::length(spine.derivative(u - 1e-9) - spine.derivative(u + 1e-9)), 1e-6);
  }
}

TEST(FlameSpine, ArcLengthMatchesDensePolyline) {
  const Spine spine = Spine::fit(bentPoints());
  const DenseCurve dense(spine, 200000);
  // The polyline of 2·10^5 chords under-measures by O(h²·curvature) ≈ 1e-10 m; the Gauss–Legendre
  // table is exact to ~1e-10 relative: 1e-8 relative leaves a wide margin.
  EXPECT_NEAR(spine.length(), dense.s.back(), 1e-8 * dense.s.back());
  for (double frac : {0.1, 0.33, 0.5, 0.77, 0.99}) {
    const double s = frac * spine.length();
    EXPECT_NEAR(spine.arcLength(spine.parameterAt(s)), s, 1e-11);
  }
}

TEST(FlameSpine, ResampleKeepsEndsAndSpacesEvenly) {
  const std::vector<SpinePoint> pts = bentPoints();
  const Spine spine = Spine::fit(pts);
  for (int n : {2, 5, 16, 40}) {
    const std::vector<SpinePoint> r = resampleSpine(pts, n);
    ASSERT_EQ(int(r.size()), n);
    // First and last unchanged, bit for bit (§4.1: "always keeping the first and last unchanged").
    EXPECT_EQ(r.front().x, pts.front().x);
    EXPECT_EQ(r.back().x, pts.back().x);
    EXPECT_EQ(r.back().age, pts.back().age);
    // Evenly spaced along the curve, measured on an independent dense polyline (10^5 chords, each
    // ~5e-6 m: nearest-sample location is within that), and on the curve (same bound).
    const DenseCurve dense(spine, 100000);
    const double step = dense.s.back() / (n - 1), tol = 2e-5;
    for (int j = 0; j < n; ++j) {
      double off = 0.0;
      const double s = dense.locate(r[std::size_t(j)].x, off);
      EXPECT_NEAR(s, j * step, tol) << "n=" << n << " j=" << j;
      EXPECT_LT(off, tol);
    }
    // Ages interpolated between neighbours stay increasing along the spine.
    for (int j = 1; j < n; ++j) EXPECT_GT(r[std::size_t(j)].age, r[std::size_t(j) - 1].age);
  }
}

TEST(FlameSpine, StraightLineAndDegenerateInputs) {
  std::vector<SpinePoint> line(2);
  line[1].x = glm::dvec3(0.0, 0.0, 0.3);
  const std::vector<SpinePoint> r = resampleSpine(line, 4);
  // Two points: the spline is the segment; 0.1 m apart up to rounding.
  for (int j = 0; j < 4; ++j) EXPECT_NEAR(r[std::size_t(j)].x.z, 0.1 * j, 1e-15);
  // Repeated points (a new particle not yet moved) are merged, not divided by zero.
  std::vector<SpinePoint> twins = {line[0], line[0], line[1], line[1]};
  for (const SpinePoint& p : resampleSpine(twins, 5)) EXPECT_TRUE(std::isfinite(p.x.z));
  std::vector<SpinePoint> still(3);  // all on the base: zero length, n copies
  for (const SpinePoint& p : resampleSpine(still, 6)) EXPECT_EQ(p.x, glm::dvec3(0.0));
}

TEST(FlameSpine, SplitKeepsPieceCountsAndEnds) {
  const std::vector<SpinePoint> pts = resampleSpine(bentPoints(), 16);
  const Spine spine = Spine::fit(pts);
  std::vector<SpinePoint> lower, upper;
  const double h = 0.3 * spine.length();
  splitSpine(pts, h, 16, lower, upper);
  EXPECT_EQ(lower.size(), 16u);
  // 16 points evenly spaced: those at j/15 > 0.3 are 11 (j = 5..15), plus the break point.
  EXPECT_EQ(upper.size(), 12u);
  EXPECT_EQ(lower.front().x, pts.front().x);
  EXPECT_EQ(upper.back().x, pts.back().x);
  EXPECT_LT(glm::length(lower.back().x - upper.front().x), 1e-12);
  EXPECT_NEAR(polylineLength(lower), h, 1e-3 * h);  // chords of a gently bent curve
  splitSpine(pts, h, 0, lower, upper);
  EXPECT_EQ(lower.size(), 6u);  // 5 points below 0.3 L plus the break point: not refilled
}

TEST(FlameBreakaway, DrawsKeepTheirBoundsAndMeans) {
  // What is checked: every split height inside [H_p, H_i] and the three means (not the shapes
  // of the distributions).
  Rng rng(3);
  const FlameHeights h{0.1, 0.3, 1.0};
  const int n = 200000;
  double sumH = 0.0, sumL = 0.0, sumW = 0.0;
  for (int i = 0; i < n; ++i) {
    const double s = drawSplitHeight(h, rng);
    ASSERT_GE(s, 0.1);
    ASSERT_LE(s, 0.3);
    sumH += s;
    sumL += drawLifespan(0.5, rng);
    sumW += drawWaitingTime(8.0, rng);
  }
  // Means: split height 0.2 (symmetric clamp at ±2σ keeps it; SE 0.05/√n ≈ 1e-4), A/4 = 0.125
  // (SE 0.142/√n ≈ 3e-4), 1/f = 0.125 (SE 3e-4); bounds are ~5 SE.
  EXPECT_NEAR(sumH / n, 0.2, 5e-4);
  EXPECT_NEAR(sumL / n, 0.125, 1.5e-3);
  EXPECT_NEAR(sumW / n, 0.125, 1.5e-3);
}

TEST(FlameWind, FieldsHaveTheirShapes) {
  const VortexWind vortex(glm::dvec3(0.0), glm::dvec3(0.0, 0.0, 2.0), /*strength=*/1.5, /*core=*/0.1);
  const glm::dvec3 v = vortex.evaluate(glm::dvec3(0.5, 0.0, 3.0), 0.0);
  EXPECT_NEAR(v.y, 1.5, 1e-12);  // counter-clockwise about +z, strength outside the core
  EXPECT_NEAR(glm::length(vortex.evaluate(glm::dvec3(0.05, 0.0, 0.0), 0.0)), 0.75, 1e-12);
  // Grid wind reproduces a linear field exactly inside (trilinear), and sums in a composite.
  VectorGrid g(glm::ivec3(4, 4, 4));
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) g(i, j, k) = glm::vec3(float(i), 0.f, 2.f * float(k));
  CompositeWind sum;
  sum.add(std::make_shared<GridWind>(g, 0.5, glm::dvec3(0.0)));
  sum.add(std::make_shared<UniformWind>(glm::dvec3(0.0, 1.0, 0.0)));
  const glm::dvec3 w = sum.evaluate(glm::dvec3(0.75 + 0.3, 1.0, 0.75 + 0.4), 0.0);
  // x = 1.05 m is index 1.6 (cell centres at (i + ½)·0.5), z = 1.15 m index 1.8: floats, 1e-6.
  EXPECT_NEAR(w.x, 1.6, 1e-6);
  EXPECT_NEAR(w.y, 1.0, 1e-12);
  EXPECT_NEAR(w.z, 3.6, 1e-5);
  MacGrid3 mac(glm::ivec3(3, 3, 3));
  mac.fill(2.f);
  EXPECT_NEAR(MacWind(mac, 0.1, glm::dvec3(0.0)).evaluate(glm::dvec3(0.12, 0.2, 0.05), 0.0).z, 2.0, 1e-6);
}

TEST(FlameWind, TurbulenceIsDivergenceFreeWithItsStrength) {
  const TurbulenceWind turb(/*strength=*/0.8, /*size=*/0.3, /*flow=*/1.0, /*seed=*/9);
  Rng rng(4);
  double sq = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const glm::dvec3 x(rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-3, 3));
    const double t = rng.uniform(0, 10);
    sq += glm::dot(turb.evaluate(x, t), turb.evaluate(x, t));
    if (i < 200) {
      // Central differences, h = 1e-5 m: truncation ~ |k|³ h² ≈ 1e-6 of the gradient scale
      // |k|·strength ≈ 17 s⁻¹; the analytic divergence is 0.
      double div = 0.0;
      for (int a = 0; a < 3; ++a) {
        glm::dvec3 d(0.0);
        d[a] = 1e-5;
        div += (turb.evaluate(x + d, t)[a] - turb.evaluate(x - d, t)[a]) / 2e-5;
      }
      EXPECT_LT(std::abs(div), 1e-4);
    }
  }
  // rms over a box 20 sizes wide: cross terms between modes average out (to a few %).
  EXPECT_NEAR(std::sqrt(sq / n), 0.8, 0.08);
}

TEST(FlameObstacle, DistancesAndPushOut) {
  const BoxSdf box(glm::dvec3(0.0), glm::dvec3(1.0, 2.0, 3.0));
  EXPECT_NEAR(box.distance(glm::dvec3(0.5, 1.0, 1.5)), -0.5, 1e-15);
  EXPECT_NEAR(box.distance(glm::dvec3(2.0, 1.0, 1.5)), 1.0, 1e-15);
  ObstacleSet set;
  set.add(std::make_shared<SphereSdf>(glm::dvec3(0.0), 0.5));
  glm::dvec3 x(0.1, 0.0, 0.0);
  EXPECT_TRUE(set.pushOut(x, 0.01, glm::dvec3(0.0)));
  EXPECT_NEAR(glm::length(x), 0.51, 1e-6);  // along ∇φ = radial; finite-difference gradient
  glm::dvec3 centre(0.0);  // ∇φ = 0: the neighbour's direction decides
  set.pushOut(centre, 0.0, glm::dvec3(0.0, -1.0, 0.0));
  EXPECT_NEAR(centre.y, -0.5, 1e-6);
  ScalarGrid phi(glm::ivec3(8, 8, 8));
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 8; ++i) phi(i, j, k) = float((k + 0.5) * 0.1 - 0.4);  // ground at z = 0.4
  set.add(std::make_shared<GridSdf>(phi, 0.1, glm::dvec3(0.0)));
  glm::dvec3 low(0.6, 0.6, 0.1);  // inside the grid, outside the sphere
  set.pushOut(low, 0.0, glm::dvec3(0.0));
  EXPECT_GE(set.distance(low), 0.0);
  EXPECT_NEAR(low.z, 0.4, 1e-5);
}

/// Expects validate() to throw std::invalid_argument whose message holds every word of `words`.
template <typename Fn>
void expectRejected(Fn&& validate, std::vector<std::string> words) {
  try {
    validate();
    ADD_FAILURE() << "accepted; expected a message with " << words.front();
  } catch (const std::invalid_argument& e) {
    for (const std::string& w : words) EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what();
  }
}

TEST(FlameParamsTest, BadSettingsAreNamedWithTheirRange) {
  FlameParams ok;
  EXPECT_NO_THROW(ok.validate());
  auto with = [](auto change) { FlameParams p; change(p); return [p] { p.validate(); }; };
  expectRejected(with([](FlameParams& p) { p.points = 1; }), {"points", "[2, 256]"});
  expectRejected(with([](FlameParams& p) { p.heightPersistent = 0.3; }), {"H_p", "[0, H_i)"});
  expectRejected(with([](FlameParams& p) { p.heightMax = 0.2; }), {"H_max", "[0.3, 1000]"});
  expectRejected(with([](FlameParams& p) { p.lifespanScale = 0.01; }), {"lifespan_scale (A)", "0.0416667, 2]"});
  expectRejected(with([](FlameParams& p) { p.lifespanScale = 3.0; }), {"(A)", "2]"});
  expectRejected(with([](FlameParams& p) { p.breakawayFrequency = -1.0; }), {"breakaway_frequency", "[0, 1000]"});
  expectRejected(with([](FlameParams& p) { p.diffusion = std::nan(""); }), {"diffusion"});
  expectRejected(with([](FlameParams& p) { p.gravity = glm::dvec3(0.0); }), {"gravity"});
  FlameSource s;
  s.radius = 0.0;
  expectRejected([s] { s.validate(3); }, {"sources[3].radius", "(0, 100]"});
  s = FlameSource();
  s.endTime = -1.0;
  expectRejected([s] { s.validate(0); }, {"sources[0].end_time", "start_time"});
  // f = 0.50 (g/2r)^½: r = 0.02 m gives 0.5·√245.25 ≈ 7.83 Hz.
  EXPECT_NEAR(ok.frequency(0.02), 0.5 * std::sqrt(9.81 / 0.04), 1e-12);
}

}  // namespace
}  // namespace plume
