// Unit tests of the least-squares streak surface ([Smoke Surfaces] §3.3 with a control net an
// artist can edit): chord-length parameters, the penalised curve fit, the surface and shot fits
// (tolerance, control points on the smoke, local support, thread count), local frames at the
// control points, and the density map's zero outside the grid (§3.4).
#include "core/parallel.h"
#include "core/rng.h"
#include "nurbs/chord_parameters.h"
#include "nurbs/density_map.h"
#include "nurbs/evaluation.h"
#include "nurbs/interpolation.h"
#include "nurbs/knots.h"
#include "nurbs/least_squares.h"
#include "nurbs/local_frames.h"
#include "nurbs/near_particles.h"
#include "nurbs/shot_fit.h"

#include "streak_shot.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

namespace plume {
namespace {

// --- chord-length parameters ---------------------------------------------------------------

TEST(NurbsChordParameters, AverageRowsAndMergeCoincidentPoints) {
  // Two rows of 4 points: row 0 spaced 1, 1, 2; row 1 spaced 0 (coincident), 1, 1.
  const std::vector<glm::vec3> p = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {4, 0, 0},
                                    {0, 1, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}};
  const std::vector<double> t = averagedChordParameters({p.data(), 4, 2, 1, 4});
  ASSERT_EQ(t.size(), 4u);
  EXPECT_DOUBLE_EQ(t[0], 0.0);
  EXPECT_DOUBLE_EQ(t[1], 0.5 * (0.25 + 0.0));
  EXPECT_DOUBLE_EQ(t[2], 0.5 * (0.5 + 0.5));
  EXPECT_DOUBLE_EQ(t[3], 1.0);
  // Across the rows (per point index): lengths 1, 1, 1, 2, all normalised to 1.
  const std::vector<double> v = averagedChordParameters({p.data(), 2, 4, 4, 1});
  EXPECT_EQ(v, (std::vector<double>{0.0, 1.0}));
  // A row of one repeated point: equal parameters would be meaningless, so uniform.
  const std::vector<glm::vec3> same(5, glm::vec3(0.3f));
  EXPECT_EQ(averagedChordParameters({same.data(), 5, 1, 1, 5}),
            (std::vector<double>{0.0, 0.25, 0.5, 0.75, 1.0}));
  EXPECT_EQ(averagedChordParameters({same.data(), 1, 1, 1, 1}), std::vector<double>{0.0});
  EXPECT_THROW(averagedChordParameters({same.data(), 0, 1, 1, 5}), std::invalid_argument);
}

// --- penalised least-squares curve ---------------------------------------------------------

/// C(t) of a B-spline on Blender's endpoint knots.
glm::dvec3 curvePoint(const std::vector<glm::dvec3>& c, int order, double t) {
  const std::vector<float> k = blenderKnots(int(c.size()), order, true);
  const BasisValues b = basisFunctions(k, int(c.size()), order, t);
  glm::dvec3 p(0.0);
  for (int r = 0; r < order; ++r) p += b.values[std::size_t(r)] * c[std::size_t(b.first + r)];
  return p;
}

TEST(NurbsLeastSquares, ReproducesACurveItCanRepresent) {
  Rng rng(3);
  std::vector<glm::dvec3> ref(9);
  for (glm::dvec3& c : ref) c = {rng.uniform(), rng.uniform(), rng.uniform()};
  const double end = 9 - 4 + 1;
  std::vector<double> t;
  std::vector<glm::dvec3> q;
  for (int i = 0; i < 50; ++i) {
    t.push_back(end * std::pow(double(i) / 49.0, 1.5));  // uneven, like particles of a plume
    q.push_back(curvePoint(ref, 4, t.back()));
  }
  const CurveFitter exact(t, 9, 4, true, /*smoothing=*/0.0);
  std::vector<glm::dvec3> c(9);
  exact.fit(q.data(), 1, c.data(), 1);
  for (int j = 0; j < 9; ++j)
    EXPECT_NEAR(glm::length(c[std::size_t(j)] - ref[std::size_t(j)]), 0.0, 1e-9);
  // The default penalty only nudges it.
  const CurveFitter smooth(t, 9, 4, true, SurfaceFitParams{}.smoothing);
  smooth.fit(q.data(), 1, c.data(), 1);
  for (std::size_t i = 0; i < q.size(); ++i)
    EXPECT_LT(glm::length(smooth.point(i, c.data(), 1) - q[i]), 0.02);
}

TEST(NurbsLeastSquares, SpansWithoutDataStayOnTheSegment) {
  // Two particles and 12 control points: BᵀB alone is singular; the penalty makes the curve the
  // straight segment, its control points evenly on it (no control point flies off).
  const glm::dvec3 a(0.1, 0.2, 0.3), b(0.4, -0.2, 1.3);
  const std::vector<glm::dvec3> q = {a, b};
  const double end = 12 - 4 + 1;
  const CurveFitter f({0.0, end}, 12, 4, true, SurfaceFitParams{}.smoothing);
  std::vector<glm::dvec3> c(12);
  f.fit(q.data(), 1, c.data(), 1);
  for (const glm::dvec3& p : c) {
    const double s = glm::dot(p - a, b - a) / glm::dot(b - a, b - a);
    EXPECT_GE(s, -1e-9);
    EXPECT_LE(s, 1.0 + 1e-9);
    EXPECT_NEAR(glm::length(a + s * (b - a) - p), 0.0, 1e-9);
  }
  EXPECT_NEAR(glm::length(f.point(0, c.data(), 1) - a), 0.0, 1e-9);
  EXPECT_NEAR(glm::length(f.point(1, c.data(), 1) - b), 0.0, 1e-9);
  // Without the penalty the same system is singular.
  EXPECT_THROW(CurveFitter({0.0, end}, 12, 4, true, 0.0), std::runtime_error);
}

TEST(NurbsLeastSquares, CoincidentParametersGiveTheMean) {
  const std::vector<glm::dvec3> q = {{1, 2, 3}, {3, 2, 1}, {2, 2, 2}};
  const CurveFitter f({0.0, 0.0, 0.0}, 5, 4, true, 1e-3);
  std::vector<glm::dvec3> c(5);
  f.fit(q.data(), 1, c.data(), 1);
  for (const glm::dvec3& p : c) EXPECT_NEAR(glm::length(p - glm::dvec3(2.0)), 0.0, 1e-12);
  EXPECT_THROW(CurveFitter({0.0, 3.0}, 5, 4, true, 1e-3), std::invalid_argument);  // outside [0, 2]
  EXPECT_THROW(CurveFitter({0.0}, 5, 7, true, 1e-3), std::invalid_argument);
  EXPECT_THROW(CurveFitter({0.0}, 5, 4, true, -1.0), std::invalid_argument);
}

// --- a shot of streaklines -----------------------------------------------------------------

constexpr float kCell = 1.f / 40.f;  // a 40³ grid over the unit domain

/// `lines` streaklines of a rising, swirling plume over `frames` frames, `steps` emissions per
/// frame, laid out as the add-on's streakline_grid: points[f][b * particles + a], oldest first,
/// particles not yet emitted stacked on the youngest (keep = 0). Particles speed up as they
/// rise (young ones crowd near the source), the oldest are held together at the top (exactly
/// coincident, like a line piling up against a closed side), and the lines fan out with age.
using Shot = StreakShot;

Shot plumeShot(int lines, int frames, int steps) {
  Shot s;
  s.lines = lines;
  s.particles = frames * steps;
  const double dt = 1.0 / 24.0 / steps;
  for (int f = 1; f <= frames; ++f) {
    const int born = f * steps;
    const std::size_t count = std::size_t(lines) * std::size_t(s.particles);
    std::vector<glm::vec3> p(count);
    std::vector<std::uint8_t> k(count, 0);
    for (int b = 0; b < lines; ++b)
      for (int a = 0; a < s.particles; ++a) {
        const int e = std::min(a, born - 1);                    // unborn: stacked on the youngest
        const double age = std::min((born - 1 - e) * dt, 2.0);  // held at the top after 2 s
        const double fan = 0.02 + 0.08 * age;
        const double phase = 2.0 * M_PI * b / lines;
        p[std::size_t(b) * s.particles + a] = glm::vec3(
            0.5 + fan * std::cos(phase + 3.0 * age) + 0.05 * std::sin(4.0 * age),
            0.5 + fan * std::sin(phase + 3.0 * age), 0.05 + 0.1 * age + 0.2 * age * age);
        k[std::size_t(b) * s.particles + a] = a < born;
      }
    s.points.push_back(std::move(p));
    s.keep.push_back(std::move(k));
  }
  return s;
}

/// Largest distance, over the control points, to the nearest kept particle (brute force).
double farthestControlPoint(const NurbsSurface& surface, const StreakGrid& g) {
  double worst = 0.0;
  for (const glm::vec4& c : surface.controlPoints) {
    double best = 1e30;
    for (int b = 0; b < g.lines; ++b)
      for (int a = 0; a < g.particles; ++a)
        if (g.kept(b, a)) best = std::min(best, double(glm::length(glm::vec3(c) - g.at(b, a))));
    worst = std::max(worst, best);
  }
  return worst;
}

TEST(NurbsNearParticles, ExactNearestDistance) {
  Rng rng(5);
  std::vector<glm::vec3> pts;
  for (int n = 0; n < 400; ++n)
    pts.emplace_back(rng.uniform(), rng.uniform(0.0, 0.2), rng.uniform(-3.0, -2.0));
  const NearParticles near(pts, 0.05);
  for (int q = 0; q < 200; ++q) {
    // Queries inside the cloud and far outside it (metres off, as a swinging net's would be).
    const double spread = q % 2 ? 1.0 : 20.0;
    const glm::vec3 x(rng.uniform(-spread, spread), rng.uniform(-spread, spread),
                      rng.uniform(-spread, spread) - 2.5);
    double best = 1e30;
    for (const glm::vec3& p : pts) best = std::min(best, glm::length(glm::dvec3(p) - glm::dvec3(x)));
    EXPECT_NEAR(near.nearest(x), best, 1e-9);
  }
  EXPECT_TRUE(std::isinf(NearParticles({}, 1.0).nearest(glm::vec3(0.f))));
  EXPECT_THROW(NearParticles(pts, 0.0), std::invalid_argument);
}

TEST(NurbsShotFit, FewerControlPointsWithinToleranceAndOnTheSmoke) {
  const Shot shot = plumeShot(/*lines=*/12, /*frames=*/48, /*steps=*/2);
  const std::vector<StreakGrid> grids = shot.grids();
  ShotFitParams params;
  params.tolerance = 0.5 * kCell;
  params.netTolerance = 1.5 * kCell;
  const NetSize size = chooseNetSize(grids, params);
  std::printf("  shot of %d lines x %d particles: net %d x %d (orders %d, %d), worst residual "
              "%.3g cells, control points within %.3g cells of the sheet and %.3g of a particle\n",
              shot.lines, shot.particles, size.nu, size.nv, size.orderU, size.orderV,
              size.maxResidual / kCell, size.netDeviation / kCell, size.netToParticles / kCell);
  EXPECT_LT(size.nu, shot.particles / 2);
  EXPECT_LE(size.nv, shot.lines);
  // Along the streaklines the fit keeps ε and δ. The 12 lines are crumpled across (no order 4 or
  // 3 across stays within δ), so the rows of the net are the lines' curves, cubic across (the
  // particle net across; order 2 before, flat between the lines): the sheet cuts the corners
  // between lines by |Δ²|/6 of their curves, within ν here.
  EXPECT_FALSE(size.particleNetU);
  EXPECT_TRUE(size.particleNetV);
  EXPECT_EQ(size.orderV, 4);
  const double epsilon = size.particleNetV ? params.particleTolerance : params.tolerance;
  for (const StreakGrid& g : grids)
    EXPECT_LE(curveFitQuality(g, size.nu, params.fit).maxResidual, params.tolerance);
  EXPECT_LE(size.maxResidual, epsilon);
  EXPECT_LE(size.netDeviation, size.particleNetV ? params.particleTolerance : params.netTolerance);
  const std::vector<SurfaceFit> fits = fitShot(grids, size, params.fit);
  double worstFitNet = 0.0, worstInterpolatedNet = 0.0;
  for (std::size_t f = 0; f < fits.size(); ++f) {
    const SurfaceFit& fit = fits[f];
    EXPECT_LE(fit.maxResidual, epsilon);
    // The residual bounds the particle's distance to the sheet: check it at the parameters.
    const SurfaceKnots k = surfaceKnots(fit.surface);
    for (int b = 0; b < shot.lines; b += 5)
      for (int a = 0; a < shot.particles; a += 7)
        if (grids[f].kept(b, a))
          EXPECT_LE(glm::length(surfacePoint(fit.surface, k, fit.paramsU[grids[f].index(b, a)],
                                             fit.paramsV[std::size_t(b)]) - grids[f].at(b, a)),
                    epsilon * 1.0001);
    const double far = farthestControlPoint(fit.surface, grids[f]);
    EXPECT_NEAR(fit.netToParticles, far, 1e-6);
    worstFitNet = std::max(worstFitNet, far);
    if (f % 8 == 7) {  // the interpolating net of the same particles (unborn stacked), to compare
      const NurbsSurface s = interpolateSurface(shot.points[f], shot.particles, shot.lines);
      worstInterpolatedNet = std::max(worstInterpolatedNet, farthestControlPoint(s, grids[f]));
    }
  }
  std::printf("  farthest control point from the particles: fit %.3g cells, interpolation %.3g "
              "cells\n", worstFitNet / kCell, worstInterpolatedNet / kCell);
  EXPECT_LT(worstFitNet, 3.0 * kCell);
}

TEST(NurbsShotFit, ParticlesNotKeptAreIgnored) {
  Shot shot = plumeShot(5, 12, 3);
  std::vector<StreakGrid> grids = shot.grids();
  const SurfaceFit stacked = fitSurface(grids[3], 9, 5, {});
  // Whatever the slots of particles not kept hold, the fit is the same.
  for (std::size_t n = 0; n < shot.keep[3].size(); ++n)
    if (!shot.keep[3][n]) shot.points[3][n] = glm::vec3(1e6f, -1e6f, std::nanf(""));
  grids = shot.grids();
  const SurfaceFit garbage = fitSurface(grids[3], 9, 5, {});
  EXPECT_EQ(stacked.surface.controlPoints, garbage.surface.controlPoints);
  EXPECT_TRUE(std::isnan(garbage.paramsU[grids[3].index(0, shot.particles - 1)]));
  // Frame 1 (3 particles per line) with a 9-point net: the penalty fills the empty spans.
  const SurfaceFit first = fitSurface(grids[0], 9, 5, {});
  EXPECT_LE(first.maxResidual, 0.05 * kCell);
  EXPECT_LT(farthestControlPoint(first.surface, grids[0]), kCell);
  // A line with nothing kept takes no part; the others still make the sheet.
  std::fill_n(shot.keep[5].begin() + 2 * shot.particles, shot.particles, std::uint8_t(0));
  const SurfaceFit holed = fitSurface(shot.grids()[5], 9, 4, {});
  EXPECT_TRUE(std::isnan(holed.paramsV[2]));
  EXPECT_LE(holed.maxResidual, kCell);
}

TEST(NurbsShotFit, CrumpledLinesStayCubicAcross) {
  // Lines ordered in a zig-zag across a band 12 cells wide: a cubic through them swings out past
  // every turn (beyond δ), so the rows become the lines' own curves (the particle net across):
  // the sheet stays C² and cuts each fold by about |Δ²p|/6 = 24/6 = 4 cells, where order 2 drew
  // creased facets.
  Shot shot = plumeShot(16, 10, 2);
  for (std::size_t f = 0; f < shot.points.size(); ++f)
    for (int b = 0; b < shot.lines; ++b)
      for (int a = 0; a < shot.particles; ++a)
        shot.points[f][std::size_t(b) * shot.particles + a].x += float((b % 2 ? 6 : -6) * kCell);
  ShotFitParams params;
  params.tolerance = 0.5 * kCell;
  params.netTolerance = 1.5 * kCell;
  const NetSize size = chooseNetSize(shot.grids(), params);
  EXPECT_EQ(size.orderV, 4);
  EXPECT_TRUE(size.particleNetV);
  EXPECT_EQ(size.nv, shot.lines);
  // Measured 5.17 cells: the interior folds are cut by 4, the folds next to the clamped ends
  // (where the end spans' basis weights the neighbours more) by most.
  EXPECT_LE(size.maxResidual, 5.3 * kCell);
  EXPECT_GE(size.maxResidual, 4.0 * kCell);
}

TEST(NurbsShotFit, MovingOneControlPointMovesTheSheetLocally) {
  const Shot shot = plumeShot(9, 20, 2);
  const std::vector<StreakGrid> grids = shot.grids();
  const SurfaceFit fit = fitSurface(grids.back(), 30, 9, {});
  NurbsSurface moved = fit.surface;
  const int i = 12, j = 4;
  moved.controlPoints[std::size_t(j) * moved.nu + i] += glm::vec4(0.1f, 0.f, 0.f, 0.f);
  // B-spline local support: N_i is non-zero only on [t_i, t_{i+k}] (endpoint knots).
  const SurfaceKnots k = surfaceKnots(fit.surface);
  const double u0 = k.u[i], u1 = k.u[i + moved.orderU], v0 = k.v[j], v1 = k.v[j + moved.orderV];
  const std::vector<float> us = blenderSamples(moved.nu, moved.orderU, true, 8);
  const std::vector<float> vs = blenderSamples(moved.nv, moved.orderV, true, 8);
  int inside = 0, changed = 0;
  for (float u : us)
    for (float v : vs) {
      const float d = glm::length(surfacePoint(moved, k, u, v) - surfacePoint(fit.surface, k, u, v));
      const bool in = u > u0 && u < u1 && v > v0 && v < v1;
      if (!in) EXPECT_EQ(d, 0.f) << "u=" << u << " v=" << v;
      inside += in;
      changed += in && d > 0.f;  // tiny basis values at the support's rim may round away
    }
  EXPECT_GT(changed, 0.9 * inside);
  // The support, 4 of 27 spans along u and 4 of 6 across, is a small share of the sheet.
  EXPECT_LE(double(inside), 0.11 * double(us.size() * vs.size()));
}

TEST(NurbsShotFit, SameResultForAnyThreadCount) {
  const Shot shot = plumeShot(10, 20, 2);
  const std::vector<StreakGrid> grids = shot.grids();
  ShotFitParams params;
  params.tolerance = 0.25 * kCell;
  params.netTolerance = kCell;
  NetSize one, two;
  std::vector<SurfaceFit> a, b;
  {
    ThreadLimit limit(1);
    one = chooseNetSize(grids, params);
    a = fitShot(grids, one, params.fit);
  }
  {
    ThreadLimit limit(2);
    two = chooseNetSize(grids, params);
    b = fitShot(grids, two, params.fit);
  }
  EXPECT_EQ(one.nu, two.nu);
  EXPECT_EQ(one.nv, two.nv);
  EXPECT_EQ(one.orderV, two.orderV);
  for (std::size_t f = 0; f < a.size(); ++f)
    EXPECT_EQ(a[f].surface.controlPoints, b[f].surface.controlPoints);
}

TEST(NurbsShotFit, RejectsBadInput) {
  Shot shot = plumeShot(3, 4, 2);
  std::vector<StreakGrid> grids = shot.grids();
  EXPECT_THROW(fitSurface(grids[0], 1, 3, {}), std::invalid_argument);
  SurfaceFitParams bad;
  bad.orderU = 7;
  EXPECT_THROW(fitSurface(grids[0], 4, 3, bad), std::invalid_argument);
  bad = {};
  bad.smoothing = -1.0;
  EXPECT_THROW(fitSurface(grids[0], 4, 3, bad), std::invalid_argument);
  bad = {};
  bad.exponentU = 2.0;
  EXPECT_THROW(fitSurface(grids[0], 4, 3, bad), std::invalid_argument);
  ShotFitParams params;
  params.tolerance = 0.0;
  EXPECT_THROW(chooseNetSize(grids, params), std::invalid_argument);
  std::fill(shot.keep[1].begin(), shot.keep[1].end(), std::uint8_t(0));  // nothing to fit
  grids = shot.grids();
  EXPECT_THROW(fitShot(grids, NetSize{4, 3, 4, 3}, {}), std::invalid_argument);
  EXPECT_THROW(chooseNetSize({}, ShotFitParams{}), std::invalid_argument);
}

// --- local frames --------------------------------------------------------------------------

TEST(NurbsLocalFrames, OrthonormalAndTurnWithTheSheet) {
  const Shot shot = plumeShot(6, 16, 2);
  const SurfaceFit fit = fitSurface(shot.grids().back(), 10, 6, {});
  const std::vector<LocalFrame> frames = controlPointFrames(fit.surface);
  ASSERT_EQ(frames.size(), fit.surface.controlPoints.size());
  const glm::mat4 turn = glm::rotate(glm::translate(glm::mat4(1.f), glm::vec3(0.3f, -0.2f, 1.f)),
                                     float(M_PI / 2), glm::normalize(glm::vec3(1.f, 2.f, 0.5f)));
  NurbsSurface turned = fit.surface;
  for (glm::vec4& p : turned.controlPoints)
    p = glm::vec4(glm::vec3(turn * glm::vec4(glm::vec3(p), 1.f)), 1.f);
  const std::vector<LocalFrame> after = controlPointFrames(turned);
  const glm::dmat3 r = glm::dmat3(glm::mat3(turn));
  for (std::size_t n = 0; n < frames.size(); ++n) {
    const LocalFrame& f = frames[n];
    ASSERT_TRUE(f.valid) << n;
    EXPECT_NEAR(glm::length(f.tangent), 1.0, 1e-12);
    EXPECT_NEAR(glm::dot(f.tangent, f.binormal), 0.0, 1e-12);
    EXPECT_NEAR(glm::length(glm::cross(f.tangent, f.binormal) - f.normal), 0.0, 1e-12);
    // The same sheet turned by R has frames turned by R (float control points: ~1e-6).
    EXPECT_NEAR(glm::length(after[n].tangent - r * f.tangent), 0.0, 1e-4);
    EXPECT_NEAR(glm::length(after[n].normal - r * f.normal), 0.0, 1e-4);
  }
  // A sheet collapsed to a point has no frame.
  NurbsSurface point = fit.surface;
  for (glm::vec4& p : point.controlPoints) p = glm::vec4(0.5f, 0.5f, 0.5f, 1.f);
  for (const LocalFrame& f : controlPointFrames(point)) EXPECT_FALSE(f.valid);
}

// --- density map outside the grid ----------------------------------------------------------

TEST(NurbsDensityMap, ZeroOutsideTheGridBox) {
  // A grid full of smoke over [0, 1]³ and a flat sheet from z = 0.5 to z = 1.5: the part above
  // the box reads 0 (the tracer gives particles there density 0), the part inside reads 1 (the
  // clamped sampler alone would read 1 everywhere).
  DensityMapParams params;
  params.cellSize = kCell;
  params.interpolation = Interpolation::Linear;
  ScalarGrid g({40, 40, 40});
  for (std::size_t n = 0; n < g.count(); ++n) g[n] = 1.f;
  std::vector<glm::vec3> q;
  for (int b = 0; b < 3; ++b)
    for (int a = 0; a < 11; ++a) q.emplace_back(0.3f + 0.2f * b, 0.5f, 0.5f + 0.1f * a);
  const NurbsSurface s = interpolateSurface(q, 11, 3);
  const SurfaceDomain dom = surfaceDomain(s);
  const std::vector<double> us = evenParameters(dom.u.start, dom.u.end, 41);
  const std::vector<double> vs = evenParameters(dom.v.start, dom.v.end, 5);
  const DensityMap map = densityMapAt(s, g, params, us, vs);
  ASSERT_EQ(map.width, 41);
  ASSERT_EQ(map.height, 5);
  const std::vector<glm::vec3> pts = surfaceGrid(s, us, vs);
  int outside = 0;
  for (std::size_t n = 0; n < pts.size(); ++n) {
    const bool out = pts[n].z > 1.f;
    outside += out;
    EXPECT_EQ(map.values[n], out ? 0.f : 1.f) << "z=" << pts[n].z;
  }
  EXPECT_GT(outside, 0);
  EXPECT_THROW(evenParameters(0.0, 1.0, 1), std::invalid_argument);
  EXPECT_THROW(densityMapAt(s, g, params, {0.5, 0.1}, vs), std::invalid_argument);
}

}  // namespace
}  // namespace plume
