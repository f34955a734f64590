// The speed-ups of Build Surfaces' fit change no result: the v step on line curves
// fitted once (fitLines + fitAcross, as chooseNetSize searches nv) is fitSurface bit for bit,
// and the nearest-particle search stays exact when its bucket table is coarsened to fit.

#include "core/rng.h"
#include "nurbs/near_particles.h"
#include "nurbs/surface_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

namespace plume {
namespace {

TEST(NurbsFitReuse, FitAcrossReusedCurvesIsFitSurface) {
  Rng rng(11);
  const int lines = 9, particles = 30;
  std::vector<glm::vec3> pts(std::size_t(lines) * particles);
  std::vector<std::uint8_t> keep(pts.size(), 1);
  for (int b = 0; b < lines; ++b)
    for (int a = 0; a < particles; ++a) {
      const double t = a / double(particles - 1);
      pts[std::size_t(b) * particles + a] =
          glm::vec3(0.1 * b + 0.01 * rng.uniform(), 0.05 * std::sin(6.0 * t + b), t);
      keep[std::size_t(b) * particles + a] = a < particles - b;  // lines of different ages
    }
  const StreakGrid g{pts.data(), keep.data(), particles, lines};
  SurfaceFitParams params;
  const LineCurves curves = fitLines(g, 12, params);
  for (int nv : {2, 4, 6, 9})
    for (int orderV : {2, 3, 4}) {
      params.orderV = orderV;
      const SurfaceFit a = fitSurface(g, 12, nv, params);
      const SurfaceFit b = fitAcross(g, curves, nv, params);
      ASSERT_EQ(a.surface.controlPoints.size(), b.surface.controlPoints.size());
      EXPECT_EQ(0, std::memcmp(a.surface.controlPoints.data(), b.surface.controlPoints.data(),
                               a.surface.controlPoints.size() * sizeof(glm::vec4)));
      EXPECT_EQ(a.maxResidual, b.maxResidual);
      EXPECT_EQ(a.netDeviation, b.netDeviation);
    }
  // Curves of another grid are refused, not read out of bounds.
  const StreakGrid smaller{pts.data(), keep.data(), particles - 1, lines};
  EXPECT_THROW(fitAcross(smaller, curves, 4, params), std::invalid_argument);
}

TEST(NurbsFitReuse, NearestStaysExactWithCoarsenedBuckets) {
  Rng rng(3);
  std::vector<glm::vec3> pts;
  for (int n = 0; n < 300; ++n)  // a long thin cloud: 1e-4 buckets would need 1e12 of them
    pts.emplace_back(rng.uniform(0.0, 100.0), rng.uniform(0.0, 0.5), rng.uniform(0.0, 0.5));
  const NearParticles near(pts, 1e-4);
  for (int q = 0; q < 200; ++q) {
    const glm::vec3 x(rng.uniform(-10.0, 110.0), rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0));
    double best = 1e30;
    for (const glm::vec3& p : pts) best = std::min(best, glm::length(glm::dvec3(p) - glm::dvec3(x)));
    EXPECT_NEAR(near.nearest(x), best, 1e-9);
  }
}

}  // namespace
}  // namespace plume
