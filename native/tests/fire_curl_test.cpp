// What makes a combustion fire curl: the Source's Flicker (source_noise.h) and Flame Vorticity
// (forces.h Confinement).

#include "solver/forces.h"
#include "solver/smoke_solver.h"
#include "solver/source_noise.h"
#include "tests/cell_balls.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

namespace plume {
namespace {

using test::ball;

SmokeParams fireParams(glm::ivec3 res) {
  SmokeParams p;
  p.resolution = res;
  p.cellSize = 1.f / float(res.x);
  p.combustion = true;
  return p;
}

TEST(SourceNoise, InRangeRepeatableAndSmooth) {
  SourceNoise noise;
  noise.scale = 0.1f;
  noise.rate = 3.f;
  float lo = 1.f, hi = 0.f, jump = 0.f;
  for (int m = 0; m < 2000; ++m) {
    const glm::vec3 p(0.013f * m, 0.007f * m, -0.003f * m);
    const double t = 0.01 * m;
    const float v = sourceNoiseValue(p, t, noise, 7, 0);
    EXPECT_EQ(v, sourceNoiseValue(p, t, noise, 7, 0));
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    // A step of a tenth of a patch moves the value little: the noise is smooth, not white.
    const float next = sourceNoiseValue(p + glm::vec3(0.01f, 0.f, 0.f), t, noise, 7, 0);
    jump = std::max(jump, std::fabs(next - v));
  }
  EXPECT_GE(lo, 0.f);
  EXPECT_LE(hi, 1.f);
  // It spans most of [0, 1] (measured 0.00-1.00), and one step changes it by at most 0.3
  // (measured 0.24).
  EXPECT_LT(lo, 0.15f);
  EXPECT_GT(hi, 0.85f);
  EXPECT_LT(jump, 0.3f);
}

TEST(SourceNoise, ChangesWithTimeSeedAndSource) {
  SourceNoise noise;
  const glm::vec3 p(0.31f, 0.12f, 0.05f);
  int timeDiffers = 0, seedDiffers = 0, streamDiffers = 0;
  for (int m = 0; m < 100; ++m) {
    const glm::vec3 q = p + glm::vec3(0.021f * m, 0.f, 0.f);
    const float v = sourceNoiseValue(q, 0.0, noise, 1, 0);
    timeDiffers += std::fabs(sourceNoiseValue(q, 1.0, noise, 1, 0) - v) > 0.05f;
    seedDiffers += std::fabs(sourceNoiseValue(q, 0.0, noise, 2, 0) - v) > 0.05f;
    streamDiffers += std::fabs(sourceNoiseValue(q, 0.0, noise, 1, 1) - v) > 0.05f;
  }
  // Independent values differ by more than 0.05 about 85% of the time (measured 82, 84, 86).
  EXPECT_GT(timeDiffers, 60);
  EXPECT_GT(seedDiffers, 60);
  EXPECT_GT(streamDiffers, 60);
}

TEST(SourceNoise, FlickerThinsTheFuelInPatches) {
  const glm::ivec3 res(24, 24, 24);
  auto sourceFuel = [&](float amount) {
    SmokeSolver solver(fireParams(res));
    SourceSettings s;
    s.fuel = 1.f;
    s.fuelNoise.amount = amount;
    s.fuelNoise.scale = 4.f / float(res.x);  // patches four cells wide
    const CellSet cells = ball(res, glm::vec3(12.f, 12.f, 6.f), 5.f);
    solver.addSource(cells, s);
    solver.applySources(0.01f);
    std::vector<float> fuel;
    for (std::uint32_t c : cells.cells) fuel.push_back(solver.fuel()[c]);
    return fuel;
  };
  for (float f : sourceFuel(0.f)) EXPECT_EQ(f, 1.f);
  const std::vector<float> thinned = sourceFuel(1.f);
  const auto [lo, hi] = std::minmax_element(thinned.begin(), thinned.end());
  double mean = 0.0;
  for (float f : thinned) mean += f;
  mean /= double(thinned.size());
  // Flicker 1 takes between none and all of the fuel, about half on average (measured: 0.04 to
  // 0.97, mean 0.58).
  EXPECT_LT(*lo, 0.2f);
  EXPECT_GT(*hi, 0.8f);
  EXPECT_GT(mean, 0.3);
  EXPECT_LT(mean, 0.7);
}

TEST(SourceNoise, FlickerOnlyActsOnFuel) {
  const glm::ivec3 res(16, 16, 16);
  SmokeSolver solver(fireParams(res));
  SourceSettings s;
  s.fuel = 1.f;
  s.density = 0.7f;
  s.fuelNoise.amount = 1.f;
  const CellSet cells = ball(res, glm::vec3(8.f, 8.f, 4.f), 3.f);
  solver.addSource(cells, s);
  solver.applySources(0.01f);
  for (std::uint32_t c : cells.cells) {
    EXPECT_EQ(solver.density()[c], 0.7f);
    EXPECT_EQ(solver.temperature()[c], 1.f);
  }
}

TEST(SourceNoise, SettingsAreValidated) {
  SourceSettings s;
  s.fuelNoise.amount = 1.5f;
  EXPECT_THROW(s.validate(), std::invalid_argument);
  s.fuelNoise.amount = 0.5f;
  s.fuelNoise.scale = 0.f;
  EXPECT_THROW(s.validate(), std::invalid_argument);
  s.fuelNoise.scale = 0.1f;
  s.fuelNoise.rate = -1.f;
  EXPECT_THROW(s.validate(), std::invalid_argument);
  s.fuelNoise.rate = 3.f;
  EXPECT_NO_THROW(s.validate());
}

/// A velocity field with a vortex tube along z (u = ω × r inside radius 4 cells).
MacGrid3 vortex(glm::ivec3 res, float h) {
  MacGrid3 u;
  u.resize(res);
  const glm::vec2 c(res.x * 0.5f, res.y * 0.5f);
  for (int k = 0; k < res.z; ++k)
    for (int j = 0; j <= res.y; ++j)
      for (int i = 0; i <= res.x; ++i) {
        const glm::vec2 r(float(i) - c.x, float(j) + 0.5f - c.y);
        const float falloff = std::exp(-glm::dot(r, r) / 16.f);
        if (i <= res.x && j < res.y) u.u()(i, j, k) = -r.y * h * falloff;
        const glm::vec2 r2(float(i) + 0.5f - c.x, float(j) - c.y);
        if (i < res.x && j <= res.y) u.v()(i, j, k) = r2.x * h * std::exp(-glm::dot(r2, r2) / 16.f);
      }
  return u;
}

TEST(FlameVorticity, EqualsUniformConfinementWhereFuelIsOne) {
  const glm::ivec3 res(16, 16, 8);
  const float h = 1.f / 16.f;
  VectorGrid omega(res), force(res);
  ScalarGrid magnitude(res), fuel(res);
  fuel.values().assign(fuel.count(), 1.f);
  MacGrid3 uniform = vortex(res, h), flame = vortex(res, h);
  Confinement a;
  a.epsilon = 3.f;
  addVorticityConfinement(uniform, nullptr, a, h, 0.1f, omega, force, magnitude);
  Confinement b;
  b.flameEpsilon = 3.f;
  b.fuel = &fuel;
  addVorticityConfinement(flame, nullptr, b, h, 0.1f, omega, force, magnitude);
  EXPECT_EQ(uniform.u().values(), flame.u().values());
  EXPECT_EQ(uniform.v().values(), flame.v().values());
  EXPECT_NE(uniform.u().values(), vortex(res, h).u().values());  // it did push
}

TEST(FlameVorticity, NothingWhereNoFuelBurns) {
  const glm::ivec3 res(16, 16, 8);
  const float h = 1.f / 16.f;
  VectorGrid omega(res), force(res);
  ScalarGrid magnitude(res), fuel(res);  // no fuel anywhere
  MacGrid3 u = vortex(res, h);
  Confinement b;
  b.flameEpsilon = 30.f;
  b.fuel = &fuel;
  addVorticityConfinement(u, nullptr, b, h, 0.1f, omega, force, magnitude);
  EXPECT_EQ(u.u().values(), vortex(res, h).u().values());
  EXPECT_EQ(u.v().values(), vortex(res, h).v().values());
}

TEST(FlameVorticity, FireWithFlickerIsTheSameOnOneAndTwoThreads) {
  const glm::ivec3 res(20, 20, 28);
  auto run = [&](int threads) {
    SmokeParams p = fireParams(res);
    p.threads = threads;
    p.flameVorticity = 24.f;
    auto solver = std::make_unique<SmokeSolver>(p);
    SourceSettings s;
    s.fuel = 1.f;
    s.density = 0.f;
    s.fuelNoise.amount = 0.8f;
    s.fuelNoise.scale = 0.15f;
    solver->addSource(ball(res, glm::vec3(10.f, 10.f, 3.f), 3.f), s);
    for (int f = 0; f < 6; ++f) solver->advanceFrame();
    return solver;
  };
  auto a = run(1), b = run(2);
  EXPECT_EQ(a->fuel().values(), b->fuel().values());
  EXPECT_EQ(a->temperature().values(), b->temperature().values());
  EXPECT_EQ(a->velocity().w().values(), b->velocity().w().values());
}

TEST(FlameVorticity, FlickerBreaksTheBurnersSymmetry) {
  // An even source over a symmetric scene keeps the fire mirror-symmetric (Solver,
  // SymmetricPlumeStaysSymmetric); Flicker breaks it.
  const glm::ivec3 res(20, 20, 28);
  auto asymmetry = [&](float amount) {
    SmokeParams p = fireParams(res);
    p.flameVorticity = 24.f;
    SmokeSolver solver(p);
    SourceSettings s;
    s.fuel = 1.f;
    s.density = 0.f;
    s.fuelNoise.amount = amount;
    s.fuelNoise.scale = 0.15f;
    solver.addSource(ball(res, glm::vec3(10.f, 10.f, 3.f), 3.f), s);
    for (int f = 0; f < 12; ++f) solver.advanceFrame();
    const ScalarGrid& t = solver.temperature();
    float peak = 0.f, err = 0.f;
    for (int k = 0; k < res.z; ++k)
      for (int j = 0; j < res.y; ++j)
        for (int i = 0; i < res.x; ++i) {
          peak = std::max(peak, t(i, j, k));
          err = std::max(err, std::fabs(t(i, j, k) - t(res.x - 1 - i, j, k)));
        }
    return err / peak;
  };
  // Measured: 2e-5 of the peak temperature without Flicker, 0.58 with 0.8.
  EXPECT_LT(asymmetry(0.f), 1e-3f);
  EXPECT_GT(asymmetry(0.8f), 0.1f);
}

}  // namespace
}  // namespace plume
