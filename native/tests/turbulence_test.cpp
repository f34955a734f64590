// What makes a smoke plume fold: the domain's Turbulence (turbulence.h) and a smoke Source's
// Breakup (source_noise.h).

#include "solver/smoke_solver.h"
#include "solver/turbulence.h"
#include "tests/cell_balls.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

namespace plume {
namespace {

using test::ball;

SmokeParams smokeParams(glm::ivec3 res) {
  SmokeParams p;
  p.resolution = res;
  p.cellSize = 1.f / float(res.x);
  return p;
}

/// Root mean square of the horizontal face velocities, m/s.
double horizontalRms(const MacGrid3& u) {
  double sum = 0.0;
  std::size_t count = 0;
  for (const ScalarGrid* g : {&u.u(), &u.v()})
    for (float v : g->values()) {
      sum += double(v) * v;
      ++count;
    }
  return std::sqrt(sum / double(count));
}

TEST(Turbulence, OffLeavesTheAirStill) {
  SmokeParams p = smokeParams(glm::ivec3(12));
  MacGrid3 u;
  u.resize(p.resolution);
  TurbulenceLattice lattice;
  addTurbulence(u, nullptr, p, 0.0, 0.1f, lattice);
  EXPECT_EQ(horizontalRms(u), 0.0);
}

TEST(Turbulence, StirsStillAirIntoSwirlsOfItsSize) {
  // A closed still box with no smoke: after one projected step the air moves, at a speed of
  // the order of A dt, and in swirls: neighbouring faces a cell apart move alike (λ = 8 cells).
  SmokeParams p = smokeParams(glm::ivec3(24));
  p.turbulence = 2.f;
  p.turbulenceScale = 8.f * p.cellSize;
  for (Boundary& b : p.boundaries) b = Boundary::Closed;
  SmokeSolver solver(p);
  solver.step(0.05f);
  const MacGrid3& u = solver.velocity();
  const double rms = horizontalRms(u);
  // Measured 0.027 m/s for A dt = 0.1 m/s: the projection keeps the swirling part, and the
  // value noise's components are mostly well inside [-1, 1].
  EXPECT_GT(rms, 0.01);
  EXPECT_LT(rms, 0.1);
  double diff = 0.0;
  std::size_t count = 0;
  for (int k = 0; k < 24; ++k)
    for (int j = 0; j < 24; ++j)
      for (int i = 1; i < 23; ++i) {
        const double d = u.u()(i + 1, j, k) - u.u()(i, j, k);
        diff += d * d;
        ++count;
      }
  // Smooth: a cell's step changes the velocity by a fraction of its size (measured 0.25 rms).
  EXPECT_LT(std::sqrt(diff / double(count)) / rms, 0.4);
}

TEST(Turbulence, ChangesWithSeedAndTime) {
  SmokeParams p = smokeParams(glm::ivec3(12));
  p.turbulence = 1.f;
  auto push = [&](std::uint64_t seed, double t) {
    SmokeParams q = p;
    q.seed = seed;
    MacGrid3 u;
    u.resize(q.resolution);
    TurbulenceLattice lattice;
    addTurbulence(u, nullptr, q, t, 0.1f, lattice);
    return u.w().values();
  };
  EXPECT_EQ(push(1, 0.0), push(1, 0.0));
  EXPECT_NE(push(1, 0.0), push(2, 0.0));
  EXPECT_NE(push(1, 0.0), push(1, 3.0));
}

TEST(Turbulence, SameOnOneAndTwoThreads) {
  const glm::ivec3 res(20, 20, 28);
  auto run = [&](int threads) {
    SmokeParams p = smokeParams(res);
    p.threads = threads;
    p.turbulence = 2.f;
    p.turbulenceScale = 0.3f;
    auto solver = std::make_unique<SmokeSolver>(p);
    SourceSettings s;
    s.smokeNoise.amount = 0.5f;
    solver->addSource(ball(res, glm::vec3(10.f, 10.f, 3.f), 3.f), s);
    for (int f = 0; f < 6; ++f) solver->advanceFrame();
    return solver;
  };
  auto a = run(1), b = run(2);
  EXPECT_EQ(a->density().values(), b->density().values());
  EXPECT_EQ(a->velocity().u().values(), b->velocity().u().values());
  EXPECT_EQ(a->velocity().w().values(), b->velocity().w().values());
}

TEST(Turbulence, SettingsAreValidated) {
  SmokeParams p = smokeParams(glm::ivec3(8));
  p.turbulence = -1.f;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p.turbulence = 1.f;
  p.turbulenceScale = 0.f;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p.turbulenceScale = 0.3f;
  p.turbulenceRate = -1.f;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p.turbulenceRate = 0.5f;
  EXPECT_NO_THROW(p.validate());
}

TEST(Breakup, ThinsTheSmokeAndHeatInPatches) {
  const glm::ivec3 res(24, 24, 24);
  SmokeSolver solver(smokeParams(res));
  SourceSettings s;
  s.density = 1.f;
  s.temperature = 2.f;
  s.smokeNoise.amount = 1.f;
  s.smokeNoise.scale = 4.f / float(res.x);
  const CellSet cells = ball(res, glm::vec3(12.f, 12.f, 6.f), 5.f);
  solver.addSource(cells, s);
  solver.applySources(0.01f);
  float lo = 1.f, hi = 0.f;
  for (std::uint32_t c : cells.cells) {
    const float rho = solver.density()[c];
    lo = std::min(lo, rho);
    hi = std::max(hi, rho);
    // Smoke and heat thin together: the same factor on both.
    EXPECT_FLOAT_EQ(solver.temperature()[c], 2.f * rho);
  }
  // Breakup 1 takes between none and all of the smoke (measured 0 to 1).
  EXPECT_LT(lo, 0.2f);
  EXPECT_GT(hi, 0.8f);
}

TEST(Breakup, NotOnASourceThatBurns) {
  // A fuel source in a combustion domain flickers instead: its smoke and heat stay even.
  const glm::ivec3 res(16, 16, 16);
  SmokeParams p = smokeParams(res);
  p.combustion = true;
  SmokeSolver solver(p);
  SourceSettings s;
  s.fuel = 1.f;
  s.density = 0.7f;
  s.smokeNoise.amount = 1.f;
  const CellSet cells = ball(res, glm::vec3(8.f, 8.f, 4.f), 3.f);
  solver.addSource(cells, s);
  solver.applySources(0.01f);
  for (std::uint32_t c : cells.cells) EXPECT_EQ(solver.density()[c], 0.7f);
}

TEST(Breakup, SettingsAreValidated) {
  SourceSettings s;
  s.smokeNoise.amount = 1.5f;
  EXPECT_THROW(s.validate(), std::invalid_argument);
  s.smokeNoise.amount = 0.5f;
  s.smokeNoise.scale = -1.f;
  EXPECT_THROW(s.validate(), std::invalid_argument);
  s.smokeNoise.scale = 0.1f;
  EXPECT_NO_THROW(s.validate());
}

}  // namespace
}  // namespace plume
