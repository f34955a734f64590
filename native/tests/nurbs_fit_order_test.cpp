// Unit tests of the order along the streaklines of the least-squares streak surface
// ([Smoke Surfaces] §3.3 with a control net an artist can edit): where the lines scatter
// (consecutive particles cells apart, zig-zagging, as at the top of the Figure-1 plume late in
// its shot) the net keeps order 4 with one control point per particle, the control points being
// the particles (the particle net: C², no facets in a close-up, Figure 7), the sheet cutting the
// corners of the zig-zags by |Δ²p|/6, where order 2 drew the same control points as flat facets;
// smooth lines keep the cubic net with fewer control points.
#include "core/parallel.h"
#include "nurbs/evaluation.h"
#include "nurbs/knots.h"
#include "nurbs/shot_fit.h"

#include "streak_shot.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace plume {
namespace {

constexpr double kCell = 1.0 / 50.0;  // the Figure-1 grid: 50³ over a 1 m domain

/// `lines` streaklines two cells apart, 2 particles emitted per frame over `frames` frames,
/// laid out as the add-on's streakline_grid (oldest first, unborn slots stacked on the youngest,
/// keep = 0 there). Particles rise one cell per emission and sway smoothly; with `scatter`, on
/// the second half of the shot the particles older than 20 emissions zig-zag ±`zigZag` cells
/// across (12: consecutive ones 24 cells apart, the incense top's scatter), and the 4 oldest have
/// left through an open side (keep = 0, positions far off).
using ZigZagShot = StreakShot;

ZigZagShot zigZagShot(int lines, int frames, bool scatter, double zigZag = 12.0) {
  ZigZagShot s;
  s.lines = lines;
  s.particles = 2 * frames;
  for (int f = 1; f <= frames; ++f) {
    const int born = 2 * f;
    const bool late = scatter && 2 * f > frames;
    std::vector<glm::vec3> p(std::size_t(lines) * std::size_t(s.particles));
    std::vector<std::uint8_t> k(p.size(), 0);
    for (int b = 0; b < lines; ++b)
      for (int a = 0; a < s.particles; ++a) {
        const int e = std::min(a, born - 1);
        const int age = born - 1 - e;
        double x = 0.5 + 3.0 * kCell * std::sin(0.15 * age);
        if (late && age > 20) x += ((a % 2) ? zigZag : -zigZag) * kCell;
        glm::vec3 q(float(x), float(0.5 + 2.0 * kCell * b), float(0.05 + kCell * age));
        const bool gone = late && e < 4;
        if (gone) q += glm::vec3(3.f, 0.f, 1.f);  // flown on past the side: not fitted
        p[std::size_t(b) * std::size_t(s.particles) + std::size_t(a)] = q;
        k[std::size_t(b) * std::size_t(s.particles) + std::size_t(a)] = a < born && !gone;
      }
    s.points.push_back(std::move(p));
    s.keep.push_back(std::move(k));
  }
  return s;
}

ShotFitParams figure1Tolerances() {
  ShotFitParams p;  // the add-on's: ε = ½ cell, δ = 1.5 cells, ν = 3 cells
  p.tolerance = 0.5 * kCell;
  p.netTolerance = 1.5 * kCell;
  p.particleTolerance = 3.0 * kCell;
  return p;
}

/// Largest distance, over the control points, to the nearest kept particle (brute force).
double farthestControlPoint(const NurbsSurface& s, const StreakGrid& g) {
  double worst = 0.0;
  for (const glm::vec4& c : s.controlPoints) {
    double best = 1e30;
    for (int b = 0; b < g.lines; ++b)
      for (int a = 0; a < g.particles; ++a)
        if (g.kept(b, a)) best = std::min(best, double(glm::length(glm::vec3(c) - g.at(b, a))));
    worst = std::max(worst, best);
  }
  return worst;
}

/// Largest |S(u_ab, v_b) − q_ab| over the kept particles, evaluated here.
double worstResidual(const SurfaceFit& fit, const StreakGrid& g) {
  const SurfaceKnots k = surfaceKnots(fit.surface);
  double worst = 0.0;
  for (int b = 0; b < g.lines; ++b)
    for (int a = 0; a < g.particles; ++a)
      if (g.kept(b, a))
        worst = std::max(worst, double(glm::length(
                                    surfacePoint(fit.surface, k, fit.paramsU[g.index(b, a)],
                                                 fit.paramsV[std::size_t(b)]) - g.at(b, a))));
  return worst;
}

TEST(NurbsFitOrder, WideScatterKeepsTheCubicParticleNet) {
  // ±12 cells (consecutive particles 24 cells apart, the incense top's scatter): the fallback was
  // order 2 through the particles, flat facets; it is now the cubic particle net on the same
  // control points, which cuts each zig-zag's corner by |Δ²p|/6 (8 cells here).
  const ZigZagShot shot = zigZagShot(/*lines=*/4, /*frames=*/40, /*scatter=*/true);
  const std::vector<StreakGrid> grids = shot.grids();
  const ShotFitParams params = figure1Tolerances();
  // A cubic net of one control point per particle misses: it swings past every zig-zag.
  SurfaceFitParams cubic;
  const CurveFitQuality worstCubic =
      curveFitQuality(grids.back(), shot.particles, cubic, nullptr);
  const std::vector<SurfaceFit> cubicFits =
      fitShot(grids, NetSize{shot.particles, shot.lines, 4, 4}, cubic);
  double cubicFar = 0.0;
  for (std::size_t f = 0; f < grids.size(); ++f)
    cubicFar = std::max(cubicFar, farthestControlPoint(cubicFits[f].surface, grids[f]));
  std::printf("  cubic, one control point per particle: residual %.2f cells, control points "
              "%.2f cells from the curve and up to %.2f cells from a particle\n",
              worstCubic.maxResidual / kCell, worstCubic.netDeviation / kCell, cubicFar / kCell);
  EXPECT_GT(cubicFar, params.particleTolerance);

  const NetSize size = chooseNetSize(grids, params);
  std::printf("  chosen: %d x %d, orders %d x %d (particle net %d), residual %.3g cells, "
              "control points %.3g cells from a particle\n", size.nu, size.nv, size.orderU,
              size.orderV, int(size.particleNetU), size.maxResidual / kCell,
              size.netToParticles / kCell);
  EXPECT_EQ(size.orderU, 4);
  EXPECT_TRUE(size.particleNetU);
  EXPECT_EQ(size.nu, shot.particles);
  const std::vector<SurfaceFit> fits = fitShot(grids, size, params.fit);
  for (std::size_t f = 0; f < grids.size(); ++f)
    EXPECT_LE(farthestControlPoint(fits[f].surface, grids[f]), 1e-5 * kCell) << f;
  // On the uniform interior knots of the cubic, C(ḡ_a) = (p_{a−1} + 4 p_a + p_{a+1}) / 6: the
  // sheet misses a kept particle by exactly |Δ²p_a| / 6, no more.
  const StreakGrid& g = grids.back();
  const SurfaceFit& last = fits.back();
  const SurfaceKnots k = surfaceKnots(last.surface);
  double worstCut = 0.0;
  for (int b = 0; b < g.lines; ++b)
    for (int a = 3; a + 3 < g.particles; ++a) {
      if (!g.kept(b, a - 1) || !g.kept(b, a) || !g.kept(b, a + 1)) continue;
      const glm::vec3 s = surfacePoint(last.surface, k, last.paramsU[g.index(b, a)],
                                       last.paramsV[std::size_t(b)]);
      const glm::vec3 d2 = g.at(b, a - 1) - 2.f * g.at(b, a) + g.at(b, a + 1);
      EXPECT_NEAR(glm::length(s - g.at(b, a)), glm::length(d2) / 6.0, 1e-4 * kCell) << b << " " << a;
      worstCut = std::max(worstCut, double(glm::length(d2)) / 6.0);
    }
  std::printf("  largest |Δ²p|/6 on the last frame: %.2f cells\n", worstCut / kCell);
  EXPECT_NEAR(worstCut, 8.0 * kCell, 0.5 * kCell);  // ⅔ of the 12-cell swing
}

TEST(NurbsFitOrder, ScatteredLinesKeepTheCubicParticleNet) {
  // A zig-zag of ±2 cells (consecutive particles 4 cells apart): no count at order 4 or 3 meets
  // ε, δ and ν (an interpolating net swings past the zig-zags, a smaller one misses them), and
  // the fallback before was order 2 through the particles, flat facets. The cubic particle net
  // cuts the corners by 2/3 of 2 cells.
  const ZigZagShot shot = zigZagShot(/*lines=*/4, /*frames=*/40, /*scatter=*/true, /*zigZag=*/2.0);
  const std::vector<StreakGrid> grids = shot.grids();
  const ShotFitParams params = figure1Tolerances();
  SurfaceFitParams quadratic;
  quadratic.orderU = 3;
  const CurveFitQuality q3 = curveFitQuality(grids.back(), shot.particles, quadratic,
                                             nullptr);
  std::printf("  quadratic, one control point per particle: residual %.2f cells, control points "
              "%.2f cells from the curve\n", q3.maxResidual / kCell, q3.netDeviation / kCell);
  EXPECT_GT(q3.netDeviation, params.netTolerance);  // order 3 misses δ: the old fallback was 2

  const NetSize size = chooseNetSize(grids, params);
  std::printf("  chosen: %d x %d, orders %d x %d (particle net %d), residual %.3g cells, net "
              "deviation %.3g cells, control points %.3g cells from a particle\n", size.nu,
              size.nv, size.orderU, size.orderV, int(size.particleNetU),
              size.maxResidual / kCell, size.netDeviation / kCell, size.netToParticles / kCell);
  EXPECT_EQ(size.orderU, 4);
  EXPECT_TRUE(size.particleNetU);
  EXPECT_EQ(size.nu, shot.particles);
  // Every control point is a particle (up to the float rounding of the interpolation across).
  EXPECT_LE(size.netToParticles, 1e-5 * kCell);
  EXPECT_GT(size.maxResidual, params.tolerance);  // the corners are cut: ε gives way
  EXPECT_NEAR(size.maxResidual, 4.0 / 3.0 * kCell, 0.05 * kCell);
  const std::vector<SurfaceFit> fits = fitShot(grids, size, params.fit);
  for (std::size_t f = 0; f < grids.size(); ++f) {
    EXPECT_EQ(fits[f].surface.orderU, 4);
    EXPECT_LE(farthestControlPoint(fits[f].surface, grids[f]), 1e-5 * kCell) << f;
    EXPECT_LE(worstResidual(fits[f], grids[f]), 4.0 / 3.0 * kCell * 1.01) << f;
  }
}

TEST(NurbsFitOrder, ParticleNetIsEveryParticleAtTheCubicsGreville) {
  const ZigZagShot shot = zigZagShot(3, 40, true, 2.0);
  const StreakGrid g = shot.grids().back();
  SurfaceFitParams p;
  p.particleNetU = true;
  p.particleNetV = true;  // the rows are the lines' curves, so the net is the particles exactly
  ASSERT_TRUE(particleNetU(g, g.particles, p));
  EXPECT_FALSE(slotsInterpolated(g, g.particles, p));
  EXPECT_FALSE(particleNetU(g, g.particles - 1, p));  // fewer control points: least squares
  const SurfaceFit fit = fitSurface(g, g.particles, g.lines, p);
  EXPECT_EQ(fit.surface.orderU, 4);
  EXPECT_EQ(fit.surface.orderV, 3);  // 3 lines
  const SurfaceKnots k = surfaceKnots(fit.surface);
  const std::vector<double> greville = grevilleAbscissae(k.u, g.particles, 4);
  for (int b = 0; b < g.lines; ++b) {
    int first = 0, last = g.particles - 1;
    while (!g.kept(b, first)) ++first;
    while (!g.kept(b, last)) --last;
    for (int a = 0; a < g.particles; ++a) {
      const int from = std::clamp(a, first, last);
      EXPECT_EQ(glm::vec3(fit.surface.controlPoints[std::size_t(b) * g.particles + a]),
                g.at(b, from)) << b << " " << a;
      if (g.kept(b, a))
        EXPECT_NEAR(fit.paramsU[g.index(b, a)], greville[std::size_t(a)], 1e-6) << b << " " << a;
    }
  }
}

TEST(NurbsFitOrder, SmoothLinesKeepTheCubicNet) {
  const ZigZagShot shot = zigZagShot(4, 40, /*scatter=*/false);
  const std::vector<StreakGrid> grids = shot.grids();
  const ShotFitParams params = figure1Tolerances();
  const NetSize size = chooseNetSize(grids, params);
  std::printf("  smooth: %d x %d of %d particles, orders %d x %d\n", size.nu, size.nv,
              shot.particles, size.orderU, size.orderV);
  EXPECT_EQ(size.orderU, 4);
  EXPECT_LT(size.nu, shot.particles / 2);
  EXPECT_LE(size.maxResidual, params.tolerance);
  EXPECT_LE(size.netToParticles, params.particleTolerance);
}

TEST(NurbsFitOrder, OrderTwoPerSlotIsEveryParticle) {
  const ZigZagShot shot = zigZagShot(3, 40, true);
  const std::vector<StreakGrid> grids = shot.grids();
  for (std::size_t f : {std::size_t(2), grids.size() - 1}) {
    const StreakGrid& g = grids[f];
    SurfaceFitParams p;
    p.orderU = p.orderV = 2;
    ASSERT_TRUE(slotsInterpolated(g, g.particles, p));
    const SurfaceFit fit = fitSurface(g, g.particles, g.lines, p);
    EXPECT_EQ(fit.maxResidual, 0.0);
    for (int b = 0; b < g.lines; ++b) {
      int first = 0, last = g.particles - 1;
      while (!g.kept(b, first)) ++first;
      while (!g.kept(b, last)) --last;
      for (int a = 0; a < g.particles; ++a) {
        // Slot a's control point: its own particle, or the nearest kept one of the line.
        const int from = std::clamp(a, first, last);
        EXPECT_EQ(glm::vec3(fit.surface.controlPoints[std::size_t(b) * g.particles + a]),
                  g.at(b, from)) << f << " " << b << " " << a;
        if (g.kept(b, a)) EXPECT_EQ(fit.paramsU[g.index(b, a)], double(a));  // ḡ_a at order 2
      }
    }
    // Order 3 per slot interpolates too, at the quadratic's Greville abscissae.
    p.orderU = 3;
    EXPECT_LT(fitSurface(g, g.particles, g.lines, p).maxResidual, 1e-5 * kCell);
    // Fewer control points than slots: the chord-length least squares as at order 4.
    EXPECT_FALSE(slotsInterpolated(g, g.particles - 1, p));
  }
}

TEST(NurbsFitOrder, SameNetForAnyThreadCount) {
  const ZigZagShot shot = zigZagShot(4, 30, true);
  const std::vector<StreakGrid> grids = shot.grids();
  NetSize one, two;
  std::vector<SurfaceFit> a, b;
  {
    ThreadLimit limit(1);
    one = chooseNetSize(grids, figure1Tolerances());
    a = fitShot(grids, one, {});
  }
  {
    ThreadLimit limit(2);
    two = chooseNetSize(grids, figure1Tolerances());
    b = fitShot(grids, two, {});
  }
  EXPECT_EQ(one.nu, two.nu);
  EXPECT_EQ(one.orderU, two.orderU);
  EXPECT_EQ(one.particleNetU, two.particleNetU);
  EXPECT_EQ(one.nv, two.nv);
  EXPECT_EQ(one.orderV, two.orderV);
  for (std::size_t f = 0; f < a.size(); ++f)
    EXPECT_EQ(a[f].surface.controlPoints, b[f].surface.controlPoints);
}

}  // namespace
}  // namespace plume
