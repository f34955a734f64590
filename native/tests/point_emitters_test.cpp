// Tests of the point emitters ([Structural Flames] §6.3 smoke): the mass they add per second is
// the requested rate, it lands around the requested place, and an empty list changes nothing.
#include "solver/point_emitters.h"
#include "solver/smoke_solver.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace plume {
namespace {

constexpr int kN = 24;
constexpr float kH = 1.f / kN;

GridFrame frame() { return GridFrame{glm::ivec3(kN), kH, glm::vec3(-0.5f), 1.f / 24.f}; }

struct Grids {
  ScalarGrid density{glm::ivec3(kN)}, temperature{glm::ivec3(kN)};
  MacGrid3 velocity;
  Grids() { velocity.resize(glm::ivec3(kN)); }
};

/// Σ ρ Δx³: the mass a point emitter's rate is given in.
double mass(const ScalarGrid& g) {
  double t = 0.0;
  for (std::size_t n = 0; n < g.count(); ++n) t += g[n];
  return t * double(kH) * kH * kH;
}

glm::dvec3 centroid(const ScalarGrid& g, const GridFrame& f) {
  glm::dvec3 c(0.0);
  double t = 0.0;
  for (int k = 0; k < kN; ++k)
    for (int j = 0; j < kN; ++j)
      for (int i = 0; i < kN; ++i) {
        const double w = g(i, j, k);
        c += w * glm::dvec3(f.origin + (glm::vec3(i, j, k) + 0.5f) * f.cellSize);
        t += w;
      }
  return c / t;
}

PointEmitter emitter(glm::vec3 at, float radius, float rate) {
  PointEmitter e;
  e.position = at;
  e.radius = radius;
  e.densityRate = rate;
  e.velocity = glm::vec3(0.f, 0.f, 0.5f);
  e.temperature = 2.f;
  return e;
}

// The mass added in one step is rate · dt for spheres inside the domain, from below one cell
// (the minimum of one cell is used) to several cells, at positions off the cell centres. The
// weights are normalized by their sum, so the only error is float rounding: the densities are
// accumulated in float (relative 6e-8 each) and the sum taken in double, 1e-5 is ample.
TEST(PointEmitters, MassPerStepIsTheRate) {
  const GridFrame f = frame();
  for (float radius : {0.f, 0.3f * kH, kH, 2.7f * kH, 5.f * kH}) {
    for (glm::vec3 at : {glm::vec3(0.f), glm::vec3(0.013f, -0.071f, 0.2f),
                         glm::vec3(-0.2f, 0.19f, -0.23f)}) {
      Grids g;
      const float rate = 3.5f, dt = 0.01f;
      emitPoints({emitter(at, radius, rate)}, f, 0.f, nullptr, dt, g.density, g.temperature,
                 g.velocity);
      EXPECT_NEAR(mass(g.density), rate * dt, 1e-5 * rate * dt) << "radius " << radius;
    }
  }
}

// Two emitters and two steps add up: mass is linear in the rates and in time.
TEST(PointEmitters, MassAddsUpOverEmittersAndSteps) {
  const GridFrame f = frame();
  Grids g;
  const std::vector<PointEmitter> list = {emitter(glm::vec3(0.1f), 2.f * kH, 1.f),
                                          emitter(glm::vec3(-0.1f, 0.f, 0.2f), kH, 4.f)};
  for (int s = 0; s < 2; ++s)
    emitPoints(list, f, 0.f, nullptr, 0.02f, g.density, g.temperature, g.velocity);
  EXPECT_NEAR(mass(g.density), 5.f * 0.04f, 1e-5 * 0.2);
}

// Emission at the right place: nothing beyond R = max(radius, Δx) of the position; the
// temperature (ambient + T) and the velocity are set exactly there; the centroid of the smoke is
// the position. The weights 1 − (d/R)² are sampled at cell centres, so for a position off the
// lattice the centroid is off by a fraction of a cell: a quarter cell bounds it for R >= 2Δx.
TEST(PointEmitters, EmitsAtThePosition) {
  const GridFrame f = frame();
  const glm::vec3 at(0.031f, -0.117f, 0.052f);
  const float radius = 3.f * kH;
  Grids g;
  emitPoints({emitter(at, radius, 1.f)}, f, 0.25f, nullptr, 0.1f, g.density, g.temperature,
             g.velocity);
  int inside = 0;
  for (int k = 0; k < kN; ++k)
    for (int j = 0; j < kN; ++j)
      for (int i = 0; i < kN; ++i) {
        const glm::vec3 x = f.origin + (glm::vec3(i, j, k) + 0.5f) * kH;
        const bool in = glm::length(x - at) < radius * (1.f - 1e-5f);
        if (!in) {
          EXPECT_EQ(g.density(i, j, k), 0.f);
          EXPECT_EQ(g.temperature(i, j, k), 0.f);
          continue;
        }
        ++inside;
        EXPECT_GT(g.density(i, j, k), 0.f);
        EXPECT_FLOAT_EQ(g.temperature(i, j, k), 2.25f);
        EXPECT_FLOAT_EQ(g.velocity.w()(i, j, k), 0.5f);
        EXPECT_FLOAT_EQ(g.velocity.w()(i, j, k + 1), 0.5f);
      }
  EXPECT_GT(inside, 50);  // (4/3) π 3³ ≈ 113 cells
  const glm::dvec3 c = centroid(g.density, f);
  EXPECT_LT(glm::length(c - glm::dvec3(at)), 0.25 * kH);
}

// A radius below one cell still emits (into the cells within one Δx), and at least one cell.
TEST(PointEmitters, TinyRadiusUsesOneCell) {
  const GridFrame f = frame();
  Grids g;
  emitPoints({emitter(glm::vec3(0.0011f, 0.002f, -0.003f), 1e-4f, 1.f)}, f, 0.f, nullptr, 0.1f,
             g.density, g.temperature, g.velocity);
  int cells = 0;
  for (std::size_t n = 0; n < g.density.count(); ++n) cells += g.density[n] > 0.f;
  EXPECT_GE(cells, 1);
  EXPECT_LE(cells, 8);  // cell centres within one Δx of a point: at most the 2×2×2 around a corner
  EXPECT_NEAR(mass(g.density), 0.1, 1e-6);
}

// Nothing when the list is empty, nor when the sphere lies wholly outside the domain; a sphere
// half outside emits only the share of its weights inside (about half, by symmetry).
TEST(PointEmitters, EmptyListAndOutside) {
  const GridFrame f = frame();
  Grids g;
  emitPoints({}, f, 0.f, nullptr, 0.1f, g.density, g.temperature, g.velocity);
  emitPoints({emitter(glm::vec3(2.f, 0.f, 0.f), 3.f * kH, 1.f)}, f, 0.f, nullptr, 0.1f,
             g.density, g.temperature, g.velocity);
  for (std::size_t n = 0; n < g.density.count(); ++n) {
    ASSERT_EQ(g.density[n], 0.f);
    ASSERT_EQ(g.temperature[n], 0.f);
  }
  for (int a = 0; a < 3; ++a)
    for (std::size_t n = 0; n < g.velocity.component(a).count(); ++n)
      ASSERT_EQ(g.velocity.component(a)[n], 0.f);
  // Centred on the +x side: the cells inside are the half x < 0.5 of a symmetric lattice.
  emitPoints({emitter(glm::vec3(0.5f, 0.f, 0.f), 4.f * kH, 1.f)}, f, 0.f, nullptr, 0.1f,
             g.density, g.temperature, g.velocity);
  EXPECT_NEAR(mass(g.density), 0.05, 1e-6);
}

// No smoke into solid cells.
TEST(PointEmitters, SkipsSolidCells) {
  const GridFrame f = frame();
  Grids g;
  FlagGrid types(glm::ivec3(kN), kFluid);
  for (int k = 0; k < kN / 2; ++k)
    for (int j = 0; j < kN; ++j)
      for (int i = 0; i < kN; ++i) types(i, j, k) = kSolid;
  emitPoints({emitter(glm::vec3(0.f), 3.f * kH, 1.f)}, f, 0.f, &types, 0.1f, g.density,
             g.temperature, g.velocity);
  for (std::size_t n = 0; n < g.density.count(); ++n)
    if (types[n] != kFluid) ASSERT_EQ(g.density[n], 0.f);
  EXPECT_NEAR(mass(g.density), 0.05, 1e-6);  // the upper half of a sphere centred on the wall
}

TEST(PointEmitters, ValidateNamesTheSetting) {
  PointEmitter e = emitter(glm::vec3(0.f), 0.1f, 1.f);
  EXPECT_NO_THROW(e.validate());
  e.densityRate = -1.f;
  EXPECT_THROW(e.validate(), std::invalid_argument);
  e.densityRate = 1.f;
  e.radius = NAN;
  EXPECT_THROW(e.validate(), std::invalid_argument);
  SmokeParams p;
  p.resolution = glm::ivec3(kN);
  p.cellSize = kH;
  SmokeSolver solver(p);
  EXPECT_THROW(solver.setPointEmitters({emitter(glm::vec3(0.f), 5.f, 1.f)}),
               std::invalid_argument);  // radius beyond the domain's 1 m side
}

// Through the solver: a closed box without buoyancy keeps all smoke, so after one frame the
// total is rate × frame time (mass conservation restores Σρ after each advection to float
// precision; 1e-4 relative covers the float accumulation over the 24³ cells and substeps).
TEST(PointEmitters, SolverFrameEmitsRateTimesFrame) {
  SmokeParams p;
  p.resolution = glm::ivec3(kN);
  p.cellSize = kH;
  p.boundaries.fill(Boundary::Closed);
  p.alpha = p.beta = 0.f;
  p.vorticity = 0.f;
  SmokeSolver solver(p);
  PointEmitter e = emitter(glm::vec3(0.5f), 2.f * kH, 2.f);
  e.velocity = glm::vec3(0.f, 0.f, 0.3f);
  solver.setPointEmitters({e});
  for (int frameIndex = 1; frameIndex <= 3; ++frameIndex) {
    ASSERT_TRUE(solver.advanceFrame());
    EXPECT_NEAR(mass(solver.density()), 2.0 * p.frameDt * frameIndex,
                1e-4 * 2.0 * p.frameDt * frameIndex);
  }
  solver.clearEmitters();
  EXPECT_TRUE(solver.pointEmitters().empty());
}

}  // namespace
}  // namespace plume
