// Unit tests of the streak-surface NURBS ([Smoke Surfaces] §3.3-3.4): Blender's knots and
// parameter rules, interpolation through every particle, Blender's tessellation, the density
// map's convergence (Figure 8) and the OpenSubdiv export.
#include "core/parallel.h"
#include "core/rng.h"
#include "nurbs/banded_lu.h"
#include "nurbs/density_map.h"
#include "nurbs/evaluation.h"
#include "nurbs/interpolation.h"
#include "nurbs/knots.h"
#include "nurbs/subdivision_export.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

namespace plume {
namespace {

// --- knots ---------------------------------------------------------------------------------

struct KnotCase {
  int n, k;
  bool endpoint;
  std::vector<float> knots;
  float start, end;  // drawn domain [knots[k-1], knots[n]]
};

// Derived by hand from calcknots() in Blender 3.4's curve.cc (endpoint: k zeros, then +1 per
// knot while order <= a <= pnts (1-based a), so the last k knots repeat; uniform: knots[a] = a).
const std::vector<KnotCase> kKnotTable = {
    {1, 1, true, {0, 1}, 0, 1},
    {2, 2, true, {0, 0, 1, 1}, 0, 1},
    {3, 2, true, {0, 0, 1, 2, 2}, 0, 2},
    {3, 3, true, {0, 0, 0, 1, 1, 1}, 0, 1},
    {4, 3, true, {0, 0, 0, 1, 2, 2, 2}, 0, 2},
    {4, 4, true, {0, 0, 0, 0, 1, 1, 1, 1}, 0, 1},
    {5, 4, true, {0, 0, 0, 0, 1, 2, 2, 2, 2}, 0, 2},
    {7, 4, true, {0, 0, 0, 0, 1, 2, 3, 4, 4, 4, 4}, 0, 4},
    {11, 4, true, {0, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 8, 8, 8}, 0, 8},
    {2, 2, false, {0, 1, 2, 3}, 1, 2},
    {3, 3, false, {0, 1, 2, 3, 4, 5}, 2, 3},
    {4, 4, false, {0, 1, 2, 3, 4, 5, 6, 7}, 3, 4},
    {5, 3, false, {0, 1, 2, 3, 4, 5, 6, 7}, 2, 5},
    {7, 4, false, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10}, 3, 7},
};

TEST(NurbsKnots, EqualBlendersCalcknots) {
  for (const KnotCase& c : kKnotTable) {
    SCOPED_TRACE(::testing::Message() << "n=" << c.n << " k=" << c.k << " endpoint=" << c.endpoint);
    EXPECT_EQ(blenderKnots(c.n, c.k, c.endpoint), c.knots);
    const KnotDomain d = blenderDomain(c.knots, c.n, c.k);
    EXPECT_EQ(d.start, c.start);
    EXPECT_EQ(d.end, c.end);
  }
}

TEST(NurbsKnots, RejectOrdersBlenderCannotDraw) {
  EXPECT_THROW(blenderKnots(3, 4, true), std::invalid_argument);
  EXPECT_THROW(blenderKnots(3, 0, true), std::invalid_argument);
  EXPECT_THROW(blenderKnots(0, 1, true), std::invalid_argument);
  EXPECT_THROW(blenderKnots(9, 7, false), std::invalid_argument);
  EXPECT_THROW(blenderSamples(4, 4, true, 0), std::invalid_argument);
}

TEST(NurbsKnots, SamplesFollowMakeFaces) {
  // BKE_nurb_makeFaces: n * resolution samples from knots[k-1] to knots[n], float step
  // accumulated in float.
  for (bool endpoint : {true, false}) {
    const std::vector<float> s = blenderSamples(7, 4, endpoint, 3);
    ASSERT_EQ(s.size(), 21u);
    const float start = endpoint ? 0.f : 3.f, end = endpoint ? 4.f : 7.f;
    const float step = (end - start) / 20.f;
    float u = start;
    for (std::size_t i = 0; i < s.size(); ++i, u += step) EXPECT_EQ(s[i], u);
    EXPECT_NEAR(s.back(), end, 1e-5f);
  }
}

TEST(NurbsKnots, GrevilleAndInterpolationParameters) {
  // Endpoint cubic on 7 points: ḡ = 0, 1/3, 1, 2, 3, 11/3, 4 — already the drawn interval.
  const std::vector<double> g = grevilleAbscissae(blenderKnots(7, 4, true), 7, 4);
  const std::vector<double> expect = {0, 1.0 / 3, 1, 2, 3, 11.0 / 3, 4};
  ASSERT_EQ(g.size(), expect.size());
  for (std::size_t i = 0; i < g.size(); ++i) EXPECT_NEAR(g[i], expect[i], 1e-12);
  EXPECT_EQ(interpolationParameters(7, 4, true), g);
  // Uniform cubic: ḡ_i = i + 2 spills out of [3, 7] at both ends; the inside ones stay, the
  // outer ones share the first/last span, and Schoenberg-Whitney t_i < τ_i < t_{i+k} holds.
  const std::vector<double> t = interpolationParameters(7, 4, false);
  const std::vector<double> tExpect = {3, 3.5, 4, 5, 6, 6.5, 7};
  EXPECT_EQ(t, tExpect);
  for (int k = 2; k <= 6; ++k)
    for (int n = k; n <= 40; ++n) {
      const std::vector<double> tau = interpolationParameters(n, k, false);
      const std::vector<float> knots = blenderKnots(n, k, false);
      for (int i = 0; i < n; ++i) {
        EXPECT_GT(tau[std::size_t(i)], knots[std::size_t(i)]) << n << " " << k << " " << i;
        EXPECT_LT(tau[std::size_t(i)], knots[std::size_t(i + k)]) << n << " " << k << " " << i;
        if (i > 0) EXPECT_GT(tau[std::size_t(i)], tau[std::size_t(i - 1)]);
      }
      EXPECT_EQ(tau.front(), double(k - 1));
      EXPECT_EQ(tau.back(), double(n));
    }
  // A 4-point uniform cubic has one drawn span, [3, 4]: the points share it evenly.
  const std::vector<double> four = interpolationParameters(4, 4, false);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(four[std::size_t(i)], 3.0 + i / 3.0, 1e-12);
}

// --- banded LU -----------------------------------------------------------------------------

TEST(NurbsBandedLu, SolvesABandedSystemThatNeedsPivoting) {
  const int n = 9, lower = 2, upper = 1;
  Rng rng(3);
  std::vector<std::vector<double>> A(n, std::vector<double>(n, 0.0));
  BandedLu lu(n, lower, upper);
  for (int i = 0; i < n; ++i)
    for (int j = std::max(0, i - lower); j <= std::min(n - 1, i + upper); ++j) {
      // A zero diagonal forces row interchanges.
      const double a = (i == j && i % 3 == 0) ? 0.0 : rng.uniform(-1.0, 1.0);
      A[std::size_t(i)][std::size_t(j)] = a;
      lu.set(i, j, a);
    }
  std::vector<glm::dvec3> x(n), b(n, glm::dvec3(0.0));
  for (int i = 0; i < n; ++i) x[std::size_t(i)] = {rng.uniform(), rng.uniform(), rng.uniform()};
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) b[std::size_t(i)] += A[std::size_t(i)][std::size_t(j)] * x[std::size_t(j)];
  lu.factor();
  lu.solve(b);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(b[std::size_t(i)][c], x[std::size_t(i)][c], 1e-10);
}

// --- interpolation -------------------------------------------------------------------------

/// Particles of nv streaklines × nu particles in a unit domain: a rising, twisting sheet with a
/// little noise, so the surface is not a trivial one.
std::vector<glm::vec3> sheet(int nu, int nv, std::uint64_t seed = 1, double noise = 0.02) {
  Rng rng(seed);
  std::vector<glm::vec3> q(std::size_t(nu) * std::size_t(nv));
  for (int v = 0; v < nv; ++v)
    for (int u = 0; u < nu; ++u) {
      const double s = nu > 1 ? double(u) / (nu - 1) : 0.0, t = nv > 1 ? double(v) / (nv - 1) : 0.0;
      q[std::size_t(v) * nu + u] =
          glm::vec3(0.5 + 0.3 * (t - 0.5) * std::cos(3.0 * s) + noise * rng.uniform(-1, 1),
                    0.5 + 0.3 * (t - 0.5) * std::sin(3.0 * s) + noise * rng.uniform(-1, 1),
                    0.1 + 0.8 * s + 0.05 * std::sin(6.0 * t) + noise * rng.uniform(-1, 1));
    }
  return q;
}

constexpr double kDomainSize = 1.0;

void expectThroughEveryParticle(int nu, int nv, bool endpointU, bool endpointV) {
  SCOPED_TRACE(::testing::Message() << "nu=" << nu << " nv=" << nv << " endpoint=" << endpointU
                                    << endpointV);
  const std::vector<glm::vec3> q = sheet(nu, nv, std::uint64_t(nu * 100 + nv));
  SurfaceSpec spec;
  spec.endpointU = endpointU;
  spec.endpointV = endpointV;
  const NurbsSurface s = interpolateSurface(q, nu, nv, spec);
  ASSERT_NO_THROW(s.validate());
  EXPECT_EQ(s.nu, std::max(nu, 2));
  EXPECT_EQ(s.nv, std::max(nv, 2));
  EXPECT_EQ(s.orderU, std::min(4, s.nu));
  EXPECT_EQ(s.orderV, std::min(4, s.nv));
  const SurfaceParameters p = particleParameters(s);
  const SurfaceKnots k = surfaceKnots(s);
  double worst = 0.0;
  // Every parameter of the (possibly padded) net maps to a data point: a padded direction is
  // constant, so both of its parameters give the single particle.
  for (int b = 0; b < s.nv; ++b)
    for (int a = 0; a < s.nu; ++a) {
      const glm::vec3 expect = q[std::size_t(std::min(b, nv - 1)) * nu + std::min(a, nu - 1)];
      const glm::vec3 got = surfacePoint(s, k, p.u[std::size_t(a)], p.v[std::size_t(b)]);
      worst = std::max(worst, double(glm::length(got - expect)));
    }
  EXPECT_LE(worst, 1e-5 * kDomainSize);
}

TEST(NurbsInterpolation, PassesThroughEveryParticleWithEndpointKnots) {
  for (int nv : {2, 3, 5, 11})
    for (int nu : {1, 2, 3, 4, 7}) expectThroughEveryParticle(nu, nv, true, true);
}

TEST(NurbsInterpolation, PassesThroughEveryParticleWithUniformKnots) {
  // Blender's uniform knots draw only [k-1, n], but the parameters spread over it still satisfy
  // Schoenberg-Whitney, so interpolation works there too.
  for (int nv : {2, 3, 5, 11})
    for (int nu : {1, 2, 3, 4, 7}) {
      expectThroughEveryParticle(nu, nv, false, false);
      expectThroughEveryParticle(nu, nv, true, false);
      expectThroughEveryParticle(nu, nv, false, true);
    }
}

TEST(NurbsInterpolation, LongStreaklinesStayAccurate) {
  for (bool endpoint : {true, false})
    for (int nu : {40, 300, 1000}) expectThroughEveryParticle(nu, 5, endpoint, endpoint);
}

TEST(NurbsInterpolation, ReproducesASurfaceItCanRepresent) {
  // Data sampled from a B-spline surface on the same knots at the same parameters gives back
  // its control points.
  NurbsSurface ref;
  ref.nu = 6;
  ref.nv = 4;
  ref.orderU = 4;
  ref.orderV = 3;
  Rng rng(9);
  for (int n = 0; n < 24; ++n)
    ref.controlPoints.push_back({rng.uniform(), rng.uniform(), rng.uniform(), 1.f});
  const SurfaceParameters p = particleParameters(ref);
  std::vector<glm::vec3> q;
  for (double v : p.v)
    for (double u : p.u) q.push_back(surfacePoint(ref, u, v));
  SurfaceSpec spec;
  spec.orderV = 3;
  const NurbsSurface s = interpolateSurface(q, 6, 4, spec);
  for (std::size_t n = 0; n < 24; ++n)
    EXPECT_NEAR(glm::length(s.controlPoints[n] - ref.controlPoints[n]), 0.f, 1e-5f);
}

TEST(NurbsInterpolation, RejectsBadInput) {
  const std::vector<glm::vec3> q = sheet(3, 2);
  EXPECT_THROW(interpolateSurface(q, 3, 3), std::invalid_argument);
  EXPECT_THROW(interpolateSurface(q, 0, 2), std::invalid_argument);
  SurfaceSpec spec;
  spec.orderU = 1;
  EXPECT_THROW(interpolateSurface(q, 3, 2, spec), std::invalid_argument);
  std::vector<glm::vec3> bad = q;
  bad[2].y = std::nanf("");
  EXPECT_THROW(interpolateSurface(bad, 3, 2), std::invalid_argument);
}

// --- evaluation ----------------------------------------------------------------------------

TEST(NurbsEvaluation, TessellationIsBlendersGridOfSurfacePoints) {
  for (bool endpoint : {true, false}) {
    const NurbsSurface s = interpolateSurface(sheet(7, 5), 7, 5, {4, 4, endpoint, !endpoint});
    const TessellatedSurface t = tessellate(s, 3, 2);
    ASSERT_EQ(t.countU, 21);
    ASSERT_EQ(t.countV, 10);
    const std::vector<float> us = blenderSamples(7, 4, endpoint, 3);
    const std::vector<float> vs = blenderSamples(5, 4, !endpoint, 2);
    for (int a = 0; a < t.countU; ++a)
      for (int b = 0; b < t.countV; ++b) {
        const glm::vec3 p = surfacePoint(s, us[std::size_t(a)], vs[std::size_t(b)]);
        EXPECT_NEAR(glm::length(t.vertices[std::size_t(a) * t.countV + b] - p), 0.f, 1e-6f);
      }
  }
  // Endpoint knots: the grid's corners are the corner particles.
  const std::vector<glm::vec3> q = sheet(4, 3);
  const TessellatedSurface t = tessellate(interpolateSurface(q, 4, 3), 2, 2);
  EXPECT_NEAR(glm::length(t.vertices.front() - q.front()), 0.f, 1e-6f);
  EXPECT_NEAR(glm::length(t.vertices.back() - q.back()), 0.f, 1e-5f);
}

TEST(NurbsEvaluation, NormalsAreUnitAndOrthogonalToTheDerivatives) {
  const NurbsSurface s = interpolateSurface(sheet(7, 5), 7, 5);
  const SurfaceKnots k = surfaceKnots(s);
  for (double u : {0.0, 0.7, 2.0, 4.0})
    for (double v : {0.0, 0.4, 1.0, 2.0}) {
      const glm::vec3 n = surfaceNormal(s, k, u, v);
      const SurfaceDerivatives d = surfaceDerivatives(s, k, u, v);
      EXPECT_NEAR(glm::length(n), 1.f, 1e-5f);
      EXPECT_NEAR(glm::dot(glm::dvec3(n), glm::normalize(d.du)), 0.0, 1e-4);
      EXPECT_NEAR(glm::dot(glm::dvec3(n), glm::normalize(d.dv)), 0.0, 1e-4);
      // Derivative against a central difference.
      const double h = 1e-4;
      const double uc = std::clamp(u, h, 4.0 - h);
      const glm::dvec3 fd = (glm::dvec3(surfacePoint(s, k, uc + h, v)) -
                             glm::dvec3(surfacePoint(s, k, uc - h, v))) / (2 * h);
      EXPECT_NEAR(glm::length(fd - surfaceDerivatives(s, k, uc, v).du), 0.0, 2e-2);
    }
  // A single particle per streakline is a curve: no normal.
  const NurbsSurface curve = interpolateSurface(sheet(1, 4), 1, 4);
  EXPECT_EQ(surfaceNormal(curve, 0.5, 0.5), glm::vec3(0.f));
}

// --- density map ---------------------------------------------------------------------------

/// A Gaussian puff sampled on a 40³ grid over the unit domain (the solver's layout).
ScalarGrid puff(DensityMapParams& params) {
  const int n = 40;
  params.origin = glm::vec3(0.f);
  params.cellSize = 1.f / n;
  ScalarGrid g({n, n, n});
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const glm::vec3 c = (glm::vec3(i, j, k) + 0.5f) / float(n);
        const glm::vec3 d = c - glm::vec3(0.55f, 0.45f, 0.5f);
        g(i, j, k) = std::exp(-glm::dot(d, d) / (2.f * 0.12f * 0.12f));
      }
  return g;
}

TEST(NurbsDensityMap, SizeAndValuesAtTheParticles) {
  DensityMapParams params;
  const ScalarGrid g = puff(params);
  const std::vector<glm::vec3> q = sheet(6, 3);
  const NurbsSurface s = interpolateSurface(q, 6, 3);
  params.samplingU = 4;
  params.samplingV = 2;
  const DensityMap map = densityMap(s, g, params);
  EXPECT_EQ(map.width, (6 - 1) * 5 + 1);
  EXPECT_EQ(map.height, (3 - 1) * 3 + 1);
  for (int b = 0; b < 3; ++b)
    for (int a = 0; a < 6; ++a) {
      const glm::vec3 p = (q[std::size_t(b) * 6 + a] - params.origin) / params.cellSize - 0.5f;
      EXPECT_NEAR(map.at(a * 5, b * 3), sample(g, p, params.interpolation), 1e-4f);
    }
  params.samplingU = -1;
  EXPECT_THROW(densityMap(s, g, params), std::invalid_argument);
}

TEST(NurbsDensityMap, ErrorFallsAsTheSamplingRateGrows) {
  // Figure 8: the interpolated map converges to the field as k grows (k = 0, 1, 2, 4, 8).
  for (Interpolation scheme : {Interpolation::Linear, Interpolation::MonotonicCubic}) {
    DensityMapParams params;
    const ScalarGrid g = puff(params);
    params.interpolation = scheme;
    const NurbsSurface s = interpolateSurface(sheet(5, 3), 5, 3);
    double previous = 1e30;
    for (int k : {0, 1, 2, 4, 8}) {
      params.samplingU = params.samplingV = k;
      const DensityMap map = densityMap(s, g, params);
      const DensityMapError e = densityMapError(s, g, params, map, 24);
      SCOPED_TRACE(::testing::Message() << "k=" << k << " rms=" << e.rms << " max=" << e.max);
      EXPECT_LT(e.rms, previous);
      previous = e.rms;
    }
    EXPECT_LT(previous, 0.01);
  }
}

TEST(NurbsDensityMap, OneDimensionalFigure8Converges) {
  auto field = [](double t) { return std::exp(-std::pow((t - 0.4) / 0.08, 2)); };
  double previous = 1e30;
  for (int k : {0, 1, 2, 4, 8}) {
    const DensityMapError e = densityMapError1D(field, 6, k);
    EXPECT_LT(e.rms, previous) << "k=" << k;
    previous = e.rms;
  }
  EXPECT_LT(previous, 0.01);
}

TEST(NurbsDensityMap, SameResultForAnyThreadCount) {
  DensityMapParams params;
  const ScalarGrid g = puff(params);
  const NurbsSurface s = interpolateSurface(sheet(40, 11), 40, 11);
  DensityMap one, two;
  {
    ThreadLimit limit(1);
    one = densityMap(s, g, params);
  }
  {
    ThreadLimit limit(2);
    two = densityMap(s, g, params);
  }
  EXPECT_EQ(one.values, two.values);
}

// --- OpenSubdiv export ---------------------------------------------------------------------

TEST(NurbsSubdivision, VertexAndQuadCounts) {
  const NurbsSurface s = interpolateSurface(sheet(5, 3), 5, 3);
  for (int level = 0; level <= 3; ++level) {
    SubdivisionParams params;
    params.level = level;
    const SubdividedMesh m = subdivideControlNet(s.controlPoints, s.nu, s.nv, params);
    const int r = 1 << level;
    EXPECT_EQ(m.vertices.size(), std::size_t(((s.nu - 1) * r + 1) * ((s.nv - 1) * r + 1)));
    EXPECT_EQ(m.quads.size(), std::size_t((s.nu - 1) * (s.nv - 1) * r * r));
    EXPECT_TRUE(m.density.empty());
  }
  SubdivisionParams bad;
  bad.level = 7;
  EXPECT_THROW(subdivideControlNet(s.controlPoints, s.nu, s.nv, bad), std::invalid_argument);
  EXPECT_THROW(subdivideControlNet(s.controlPoints, s.nu + 1, s.nv, {}), std::invalid_argument);
}

/// Distance from p to the surface, by a dense grid search then local refinement.
double distanceToSurface(const NurbsSurface& s, glm::vec3 p) {
  const SurfaceDomain d = surfaceDomain(s);
  const SurfaceKnots k = surfaceKnots(s);
  const int n = 50;
  double best = 1e30, bu = 0, bv = 0;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double u = d.u.start + (d.u.end - d.u.start) * i / n;
      const double v = d.v.start + (d.v.end - d.v.start) * j / n;
      const double e = glm::length(surfacePoint(s, k, u, v) - p);
      if (e < best) best = e, bu = u, bv = v;
    }
  double hu = (d.u.end - d.u.start) / n, hv = (d.v.end - d.v.start) / n;
  for (int it = 0; it < 24; ++it, hu *= 0.5, hv *= 0.5)
    for (int i = -2; i <= 2; ++i)
      for (int j = -2; j <= 2; ++j) {
        const double u = std::clamp(bu + i * hu * 0.5, double(d.u.start), double(d.u.end));
        const double v = std::clamp(bv + j * hv * 0.5, double(d.v.start), double(d.v.end));
        const double e = glm::length(surfacePoint(s, k, u, v) - p);
        if (e < best) best = e, bu = u, bv = v;
      }
  return best;
}

TEST(NurbsSubdivision, LimitSurfaceIsCloseToTheNurbsSurface) {
  // Catmull-Clark's limit is the uniform cubic B-spline of the net while the NURBS has clamped
  // knots: they differ a little, most near the boundary. A smooth sheet and a noisy one.
  for (double noise : {0.0, 0.02}) {
    const std::vector<glm::vec3> q = sheet(7, 5, 1, noise);
    const NurbsSurface s = interpolateSurface(q, 7, 5);
    SubdivisionParams params;
    params.level = 3;
    const SubdividedMesh m = subdivideControlNet(s.controlPoints, s.nu, s.nv, params);
    double worst = 0.0, sum = 0.0;
    for (const glm::vec3& p : m.vertices) {
      const double e = distanceToSurface(s, p);
      worst = std::max(worst, e);
      sum += e;
    }
    const double mean = sum / double(m.vertices.size());
    EXPECT_LT(worst, (noise == 0.0 ? 0.01 : 0.04) * kDomainSize) << "noise " << noise;
    EXPECT_LT(mean, (noise == 0.0 ? 0.002 : 0.01) * kDomainSize) << "noise " << noise;
    std::printf("limit vs NURBS (noise %.2f): worst %.5f mean %.5f\n", noise, worst, mean);
    // EDGE_AND_CORNER interpolates the corners, and with endpoint knots so does the NURBS.
    const glm::vec3 corners[4] = {q[0], q[6], q[28], q[34]};
    for (const glm::vec3& c : corners) {
      double nearest = 1e30;
      for (const glm::vec3& p : m.vertices) nearest = std::min(nearest, double(glm::length(p - c)));
      EXPECT_LT(nearest, 1e-5);
    }
  }
}

TEST(NurbsSubdivision, PlanarNetStaysPlanarAndDensityFollowsTheMap) {
  // An affine net (control points in a plane, evenly spaced): Catmull-Clark with
  // EDGE_AND_CORNER reproduces affine functions, so the mesh stays in the plane and a column
  // coordinate refined like a primvar stays proportional to x.
  const int nu = 5, nv = 3;
  std::vector<glm::vec4> net;
  std::vector<glm::vec3> q;
  for (int v = 0; v < nv; ++v)
    for (int u = 0; u < nu; ++u) {
      q.push_back({0.1f * u, 0.2f * v, 0.3f + 0.05f * u - 0.1f * v});
      net.push_back(glm::vec4(q.back(), 1.f));
    }
  // A density image with k_u = 4, k_v = 2 that grows linearly with the column.
  const int width = (nu - 1) * 5 + 1, height = (nv - 1) * 3 + 1;
  std::vector<float> image(std::size_t(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) image[std::size_t(y) * width + x] = float(x) / (width - 1);
  SubdivisionParams params;
  params.level = 2;
  const SubdividedMesh m = subdivideControlNet(net, nu, nv, params, image, width, height);
  ASSERT_EQ(m.density.size(), m.vertices.size());
  const glm::vec3 normal = glm::normalize(glm::cross(glm::vec3(0.1f, 0.f, 0.05f), glm::vec3(0.f, 0.2f, -0.1f)));
  for (std::size_t n = 0; n < m.vertices.size(); ++n) {
    EXPECT_NEAR(glm::dot(m.vertices[n] - q[0], normal), 0.f, 1e-5f);
    // The image column follows x here (x = 0.1 u and column = 5 u).
    EXPECT_NEAR(m.density[n], m.vertices[n].x / 0.4f, 1e-4f);
  }
  EXPECT_THROW(subdivideControlNet(net, nu, nv, params, image, width - 1, height),
               std::invalid_argument);
}

}  // namespace
}  // namespace plume
