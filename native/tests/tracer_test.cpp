/// \file tracer_test.cpp
/// Streakline tracers ([Smoke Surfaces] §3.2): point sources in cells, exact transport in a
/// uniform field, second-order convergence in a rotating field, emission counts, boundaries,
/// the frame driver against SmokeSolver::advanceFrame, determinism across thread counts.

#include "core/parallel.h"
#include "core/rng.h"
#include "solver/smoke_solver.h"
#include "tracers/point_sources.h"
#include "tracers/streak_tracer.h"
#include "tracers/tracer_driver.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>

namespace plume {
namespace {

GridFrame unitGrid(int n) { return GridFrame{glm::ivec3(n), 1.f / float(n), glm::vec3(0.f), 1.f / 24.f}; }

std::array<Boundary, 6> allSides(Boundary b) { return {b, b, b, b, b, b}; }

/// Fills a MAC grid with velocity(x) at each face centre (world positions).
template <typename F>
void fillVelocity(MacGrid3& mac, const GridFrame& g, F velocity) {
  mac.resize(g.resolution);
  for (int a = 0; a < 3; ++a) {
    ScalarGrid& c = mac.component(a);
    const glm::ivec3 s = c.size();
    for (int k = 0; k < s.z; ++k)
      for (int j = 0; j < s.y; ++j)
        for (int i = 0; i < s.x; ++i) {
          glm::vec3 p = glm::vec3(i, j, k) + 0.5f;
          p[a] -= 0.5f;  // faces sit half a cell below the centre on their own axis
          c(i, j, k) = velocity(g.origin + p * g.cellSize)[a];
        }
  }
}

TEST(PointSources, UniformInTheirCellsAndDeterministic) {
  const glm::ivec3 res(5, 4, 3);
  const float h = 0.1f;
  const glm::vec3 origin(-1.f, 2.f, 0.5f);
  CellSet cells;
  cells.cells = {0, 7, 59};
  const auto p = randomPointsInCells(cells, res, h, origin, 20, 42, 3);
  ASSERT_EQ(p.size(), 60u);
  glm::vec3 mean(0.f);
  for (std::size_t n = 0; n < p.size(); ++n) {
    const std::uint32_t c = cells.cells[n / 20];
    const glm::vec3 lo = origin + glm::vec3(c % 5, (c / 5) % 4, c / 20) * h;
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(p[n][a], lo[a]);
      EXPECT_LE(p[n][a], lo[a] + h);
    }
    mean += (p[n] - lo) / h;
  }
  mean /= float(p.size());
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(mean[a], 0.5f, 0.12f);
  // Same arguments, same points; another stream or seed, other points.
  EXPECT_EQ(std::memcmp(p.data(), randomPointsInCells(cells, res, h, origin, 20, 42, 3).data(),
                        p.size() * sizeof(glm::vec3)), 0);
  EXPECT_NE(p[0], randomPointsInCells(cells, res, h, origin, 20, 42, 4)[0]);
  EXPECT_NE(p[0], randomPointsInCells(cells, res, h, origin, 20, 43, 3)[0]);
  // The first cell's points do not depend on the cells after it (consumed in cell order).
  CellSet first;
  first.cells = {0};
  const auto q = randomPointsInCells(first, res, h, origin, 20, 42, 3);
  EXPECT_EQ(std::memcmp(p.data(), q.data(), q.size() * sizeof(glm::vec3)), 0);
}

TEST(PointSources, BadArgumentsNameTheSetting) {
  CellSet cells;
  cells.cells = {0};
  auto message = [&](auto call) {
    try {
      call();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  EXPECT_NE(message([&] { randomPointsInCells(cells, glm::ivec3(2), 0.1f, glm::vec3(0.f), 0, 1); })
                .find("point_sources"), std::string::npos);
  EXPECT_NE(message([&] { randomPointsInCells(cells, glm::ivec3(2), -1.f, glm::vec3(0.f), 4, 1); })
                .find("cell_size"), std::string::npos);
  cells.cells = {8};
  EXPECT_NE(message([&] { randomPointsInCells(cells, glm::ivec3(2), 0.1f, glm::vec3(0.f), 4, 1); })
                .find("outside the grid"), std::string::npos);
}

TEST(StreakParams, ValidateNamesTheSetting) {
  StreakParams p;
  EXPECT_NO_THROW(p.validate());
  p.emissionPeriod = 0;
  try {
    p.validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("emission_period must be in [1, 100000]"), std::string::npos);
  }
  EXPECT_THROW(StreakTracer(p, unitGrid(8), allSides(Boundary::Open)), std::invalid_argument);
}

void expectNear(glm::vec3 a, glm::vec3 b, float tol) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], tol) << "component " << c;
}

TEST(StreakTracer, UniformFieldMovesParticlesExactly) {
  for (Interpolation scheme : {Interpolation::Linear, Interpolation::MonotonicCubic}) {
    const GridFrame g = unitGrid(16);
    const glm::vec3 v(0.3f, -0.2f, 0.1f);
    MacGrid3 vel;
    fillVelocity(vel, g, [&](glm::vec3) { return v; });
    ScalarGrid density(g.resolution, 0.5f);
    StreakParams params;
    params.interpolation = scheme;
    StreakTracer t(params, g, allSides(Boundary::Open));
    const glm::vec3 source(0.4f, 0.6f, 0.3f);
    t.addPointSources({source}, {0}, {});
    const float dt = 0.05f;
    const int steps = 10;
    for (int s = 0; s < steps; ++s) t.step(vel, vel, density, dt);
    const StreakFrame f = t.snapshot();
    ASSERT_EQ(f.counts, std::vector<int>{steps + 1});
    // Particle e was emitted at instant e and has travelled (steps - e) steps.
    for (int e = 0; e <= steps; ++e) {
      expectNear(f.positions[std::size_t(e)], source + v * (dt * float(steps - e)), 1e-5f);
      EXPECT_FLOAT_EQ(f.density[std::size_t(e)], 0.5f);
      EXPECT_EQ(f.outside[std::size_t(e)], 0);
    }
  }
}

TEST(StreakTracer, TimeVaryingUniformFieldIsIntegratedExactly) {
  // u(t) = a + b t: the midpoint rule with the mean of the start and end fields is exact.
  const GridFrame g = unitGrid(16);
  const glm::vec3 a(0.2f, 0.1f, -0.1f), b(0.5f, -0.3f, 0.2f);
  StreakParams params;
  params.emissionPeriod = 1000;  // one particle
  StreakTracer t(params, g, allSides(Boundary::Open));
  const glm::vec3 source(0.3f, 0.5f, 0.6f);
  t.addPointSources({source}, {0}, {});
  ScalarGrid density(g.resolution, 0.f);
  MacGrid3 before, after;
  const float dt = 0.1f;
  for (int s = 0; s < 8; ++s) {
    const float t0 = dt * float(s);
    fillVelocity(before, g, [&](glm::vec3) { return a + b * t0; });
    fillVelocity(after, g, [&](glm::vec3) { return a + b * (t0 + dt); });
    t.step(before, after, density, dt);
  }
  const float T = 0.8f;
  expectNear(t.snapshot().positions[0], source + a * T + 0.5f * b * T * T, 2e-6f);
}

/// Error after one revolution-fraction of solid-body rotation about the domain's centre.
float rotationError(int steps, Interpolation scheme) {
  const GridFrame g = unitGrid(32);
  const glm::vec3 centre(0.5f);
  const float omega = 1.f;
  MacGrid3 vel;
  fillVelocity(vel, g, [&](glm::vec3 x) {
    return glm::vec3(-omega * (x.y - centre.y), omega * (x.x - centre.x), 0.f);
  });
  ScalarGrid density(g.resolution, 0.f);
  StreakParams params;
  params.emissionPeriod = 100000;
  params.interpolation = scheme;
  StreakTracer t(params, g, allSides(Boundary::Open));
  const float r = 0.25f;
  t.addPointSources({centre + glm::vec3(r, 0.f, 0.f)}, {0}, {});
  const float T = 1.f, dt = T / float(steps);
  for (int s = 0; s < steps; ++s) t.step(vel, vel, density, dt);
  const glm::vec3 exact = centre + glm::vec3(r * std::cos(omega * T), r * std::sin(omega * T), 0.f);
  return glm::length(t.snapshot().positions[0] - exact);
}

TEST(StreakTracer, MidpointRuleIsSecondOrderInTime) {
  for (Interpolation scheme : {Interpolation::Linear, Interpolation::MonotonicCubic}) {
    const float e1 = rotationError(10, scheme), e2 = rotationError(20, scheme),
                e3 = rotationError(40, scheme);
    const float o1 = std::log2(e1 / e2), o2 = std::log2(e2 / e3);
    std::printf("[ rotation ] errors %.3g %.3g %.3g, orders %.2f %.2f\n", e1, e2, e3, o1, o2);
    EXPECT_GE(o1, 1.8f);
    EXPECT_GE(o2, 1.8f);
    EXPECT_LT(e1, 1e-3f);
  }
}

TEST(StreakTracer, EmissionCountIsFloorOfStepsOverPeriodPlusOne) {
  const GridFrame g = unitGrid(8);
  MacGrid3 vel;
  fillVelocity(vel, g, [](glm::vec3) { return glm::vec3(0.f, 0.f, 0.1f); });
  ScalarGrid density(g.resolution, 1.f);
  for (int period : {1, 2, 3, 7}) {
    StreakParams params;
    params.emissionPeriod = period;
    StreakTracer t(params, g, allSides(Boundary::Open));
    const std::vector<glm::vec3> sources{{0.2f, 0.2f, 0.1f}, {0.7f, 0.4f, 0.2f}, {0.5f, 0.5f, 0.5f}};
    EXPECT_EQ(t.addPointSources(sources, {0, 1, 1}, {}), 0);
    EXPECT_EQ(t.particlesPerSource(), 1);
    for (int s = 1; s <= 15; ++s) {
      t.step(vel, vel, density, 0.01f);
      const int expected = s / period + 1;
      const StreakFrame f = t.snapshot();
      ASSERT_EQ(f.counts, std::vector<int>(3, expected)) << "period " << period << " step " << s;
      ASSERT_EQ(f.positions.size(), std::size_t(3 * expected));
      EXPECT_EQ(f.groups, (std::vector<int>{0, 1, 1}));
      // The youngest particle sits at its source right after an emission step.
      if (s % period == 0)
        for (int src = 0; src < 3; ++src)
          EXPECT_EQ(f.positions[std::size_t(src * expected + expected - 1)], sources[std::size_t(src)]);
    }
  }
}

TEST(StreakTracer, NewbornParticlesLeaveWithTheSourceVelocity) {
  // k1 of a newborn particle is its source's velocity; the midpoint velocity comes from the fields.
  const GridFrame g = unitGrid(8);
  MacGrid3 still;
  still.resize(g.resolution);
  still.fill(0.f);
  ScalarGrid density(g.resolution, 0.f);
  StreakTracer t(StreakParams{}, g, allSides(Boundary::Open));
  const glm::vec3 source(0.5f), v0(0.f, 0.f, 2.f);
  t.addPointSources({source}, {0}, {v0});
  t.step(still, still, density, 0.1f);
  const StreakFrame f = t.snapshot();
  // The midpoint velocity is sampled from the fields, which are still: the particle stays.
  EXPECT_EQ(f.positions[0], source);
  // With a field that is v0 everywhere, the first step moves it by exactly Δt v0.
  MacGrid3 moving;
  fillVelocity(moving, g, [&](glm::vec3) { return v0; });
  StreakTracer u(StreakParams{}, g, allSides(Boundary::Open));
  u.addPointSources({source}, {0}, {v0});
  u.step(still, moving, density, 0.1f);
  // k1 = v0 (source velocity, although the start field is still), midpoint = ½(0 + v0).
  expectNear(u.snapshot().positions[0], source + 0.1f * 0.5f * v0, 1e-6f);
}

TEST(StreakTracer, OpenSidesReleaseParticlesClosedSidesClamp) {
  const GridFrame g = unitGrid(8);
  std::array<Boundary, 6> sides = allSides(Boundary::Closed);
  sides[kPosX] = Boundary::Open;
  MacGrid3 vel;
  fillVelocity(vel, g, [](glm::vec3) { return glm::vec3(1.f, 0.f, 0.5f); });
  ScalarGrid density(g.resolution, 0.f);
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 8; ++i) density(i, j, k) = float(i);
  StreakParams params;
  params.emissionPeriod = 1000;
  params.interpolation = Interpolation::Linear;
  StreakTracer t(params, g, sides);
  // Source A leaves through the open +x side at step 2; source B reaches the closed +z side at
  // step 3, slides under it and leaves through +x at step 8. No position lands exactly on a side.
  t.addPointSources({{0.85f, 0.5f, 0.2f}, {0.25f, 0.5f, 0.88f}}, {0, 0}, {});
  for (int s = 0; s < 5; ++s) t.step(vel, vel, density, 0.1f);
  StreakFrame f = t.snapshot();
  // A left at step 2 and goes on with its exit velocity (1, 0, 0.5): 5 steps of 0.1 s in all.
  EXPECT_EQ(f.outside[0], 1);
  EXPECT_NEAR(f.positions[0].x, 1.35f, 1e-5f);
  EXPECT_NEAR(f.positions[0].z, 0.45f, 1e-5f);
  EXPECT_EQ(f.density[0], 0.f);
  // B is clamped under the closed lid and keeps moving in x.
  EXPECT_EQ(f.outside[1], 0);
  EXPECT_FLOAT_EQ(f.positions[1].z, 1.f);
  EXPECT_NEAR(f.positions[1].x, 0.75f, 1e-6f);
  EXPECT_GT(f.density[1], 0.f);
  for (int s = 0; s < 3; ++s) t.step(vel, vel, density, 0.1f);
  f = t.snapshot();
  EXPECT_NEAR(f.positions[0].x, 1.65f, 1e-5f);
  EXPECT_NEAR(f.positions[0].z, 0.6f, 1e-5f);
  // B has now left through +x too, still held under the lid in z.
  EXPECT_EQ(f.outside[1], 1);
  EXPECT_NEAR(f.positions[1].x, 1.05f, 1e-5f);
  EXPECT_FLOAT_EQ(f.positions[1].z, 1.f);
}

TEST(StreakTracer, DensityIsSampledAtTheParticle) {
  const GridFrame g = unitGrid(10);
  MacGrid3 vel;
  fillVelocity(vel, g, [](glm::vec3) { return glm::vec3(0.2f, 0.f, 0.f); });
  ScalarGrid density(g.resolution);
  for (int k = 0; k < 10; ++k)
    for (int j = 0; j < 10; ++j)
      for (int i = 0; i < 10; ++i) density(i, j, k) = 0.1f * float(i) + 0.02f * float(k);
  StreakParams params;
  params.interpolation = Interpolation::Linear;
  StreakTracer t(params, g, allSides(Boundary::Open));
  t.addPointSources({{0.3f, 0.5f, 0.45f}}, {0}, {});
  for (int s = 0; s < 4; ++s) t.step(vel, vel, density, 0.25f);
  const StreakFrame f = t.snapshot();
  for (std::size_t n = 0; n < f.positions.size(); ++n) {
    const glm::vec3 c = f.positions[n] * 10.f - 0.5f;  // cell coordinates
    EXPECT_NEAR(f.density[n], 0.1f * c.x + 0.02f * c.z, 1e-5f);
  }
}

TEST(StreakTracer, RejectsLateSourcesOutsidePointsAndBadGrids) {
  const GridFrame g = unitGrid(8);
  StreakTracer t(StreakParams{}, g, allSides(Boundary::Open));
  EXPECT_THROW(t.addPointSources({{1.5f, 0.5f, 0.5f}}, {0}, {}), std::invalid_argument);
  EXPECT_THROW(t.addPointSources({{0.5f, 0.5f, 0.5f}}, {0, 1}, {}), std::invalid_argument);
  EXPECT_EQ(t.addPointSources({{0.5f, 0.5f, 0.5f}}, {0}, {}), 0);
  EXPECT_EQ(t.addPointSources({{0.4f, 0.5f, 0.5f}}, {0}, {}), 1);  // still before any step
  MacGrid3 vel(g.resolution), small(glm::ivec3(4));
  vel.fill(0.f);
  small.fill(0.f);
  ScalarGrid density(g.resolution, 0.f);
  EXPECT_THROW(t.step(small, vel, density, 0.1f), std::invalid_argument);
  EXPECT_THROW(t.step(vel, vel, density, 0.f), std::invalid_argument);
  t.step(vel, vel, density, 0.1f);
  EXPECT_THROW(t.addPointSources({{0.5f, 0.5f, 0.5f}}, {0}, {}), std::invalid_argument);
}

// --- with the solver --------------------------------------------------------------------------

SmokeParams plumeParams(int threads) {
  SmokeParams p;
  p.resolution = glm::ivec3(16, 16, 24);
  p.cellSize = 1.f / 16.f;
  p.threads = threads;
  p.seed = 7;
  return p;
}

CellSet sourceCells(glm::ivec3 res) {
  CellSet s;
  for (int k = 1; k < 3; ++k)
    for (int j = 6; j < 10; ++j)
      for (int i = 6; i < 10; ++i) s.cells.push_back(std::uint32_t(i + res.x * (j + res.y * k)));
  return s;
}

SourceSettings sourceSettings() {
  SourceSettings s;
  s.density = 1.f;
  s.temperature = 2.f;
  s.velocity = glm::vec3(0.f, 0.f, 0.5f);
  return s;
}

std::unique_ptr<SmokeSolver> plumeSolver(int threads) {
  auto solver = std::make_unique<SmokeSolver>(plumeParams(threads));
  solver->addSource(sourceCells(solver->params().resolution), sourceSettings());
  return solver;
}

std::unique_ptr<StreakTracer> plumeTracer(const SmokeSolver& solver) {
  const SmokeParams& p = solver.params();
  auto tracer = std::make_unique<StreakTracer>(StreakParams{}, p);
  const CellSet cells = sourceCells(p.resolution);
  const auto points = randomPointsInCells(cells, p.resolution, p.cellSize, p.origin, 4, p.seed, 0);
  tracer->addPointSources(points, std::vector<int>(points.size(), 0),
                          std::vector<glm::vec3>(points.size(), sourceSettings().velocity));
  return tracer;
}

TEST(TracerDriver, SameSolverStateAsAdvanceFrame) {
  auto a = plumeSolver(0), b = plumeSolver(0);
  auto tracer = plumeTracer(*b);
  long long steps = 0;
  for (int f = 0; f < 4; ++f) {
    ASSERT_TRUE(a->advanceFrame());
    ASSERT_TRUE(advanceFrameWithTracers(*b, *tracer));
    const StepStats stats = b->lastStats();
    EXPECT_EQ(stats.substeps, a->lastStats().substeps);
    EXPECT_EQ(stats.pressureIterations, a->lastStats().pressureIterations);
    steps += stats.substeps;
  }
  EXPECT_EQ(b->frame(), 4);
  EXPECT_EQ(a->density().values(), b->density().values());
  EXPECT_EQ(a->velocity().w().values(), b->velocity().w().values());
  EXPECT_EQ(tracer->steps(), steps);
  EXPECT_EQ(tracer->particlesPerSource(), int(steps) + 1);
  // The plume rises: the oldest particles are well above their sources.
  const StreakFrame f = tracer->snapshot();
  double rise = 0.0;
  for (int s = 0; s < f.sourceCount(); ++s)
    rise += f.positions[std::size_t(s * f.counts[0])].z - tracer->pointSources()[std::size_t(s)].position.z;
  EXPECT_GT(rise / f.sourceCount(), 0.04);
}

TEST(TracerDriver, CancelReturnsFalseAndKeepsTheFrame) {
  auto solver = plumeSolver(0);
  auto tracer = plumeTracer(*solver);
  tracer->cancel();
  EXPECT_FALSE(advanceFrameWithTracers(*solver, *tracer));
  EXPECT_EQ(solver->frame(), 0);
  EXPECT_EQ(tracer->steps(), 0);
  // The request was consumed: the next frame runs.
  EXPECT_TRUE(advanceFrameWithTracers(*solver, *tracer));
  EXPECT_EQ(solver->frame(), 1);
}

TEST(TracerDriver, SolverCancelStopsTheDriver) {
  auto solver = plumeSolver(0);
  auto tracer = plumeTracer(*solver);
  solver->cancel();
  EXPECT_FALSE(advanceFrameWithTracers(*solver, *tracer));
  EXPECT_TRUE(advanceFrameWithTracers(*solver, *tracer));
}

TEST(TracerDriver, SameStreaksWithOneAndTwoThreads) {
  StreakFrame frames[2];
  for (int threads : {1, 2}) {
    auto solver = plumeSolver(threads);
    auto tracer = plumeTracer(*solver);
    for (int f = 0; f < 4; ++f) ASSERT_TRUE(advanceFrameWithTracers(*solver, *tracer));
    frames[threads - 1] = tracer->snapshot();
  }
  EXPECT_EQ(frames[0].counts, frames[1].counts);
  ASSERT_EQ(frames[0].positions.size(), frames[1].positions.size());
  EXPECT_EQ(std::memcmp(frames[0].positions.data(), frames[1].positions.data(),
                        frames[0].positions.size() * sizeof(glm::vec3)), 0);
  EXPECT_EQ(frames[0].density, frames[1].density);
}

}  // namespace
}  // namespace plume
