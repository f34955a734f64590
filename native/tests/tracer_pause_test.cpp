/// \file tracer_pause_test.cpp
/// Pausing particle emission ([Smoke Surfaces] §3.2, Figure 10: "particle emission was turned
/// off" for 60 frames): a paused tracer adds no particles at its emission instants, the particles
/// already emitted keep moving exactly as before, and emission resumes on the next instant.

#include "tracers/streak_tracer.h"

#include <gtest/gtest.h>

#include <vector>

namespace plume {
namespace {

/// 8³ unit cube, open on every side.
GridFrame grid() { return GridFrame{glm::ivec3(8), 0.125f, glm::vec3(0.f), 1.f / 24.f}; }

/// Upward flow growing linearly with height, w(z) = a + b z: trilinear sampling reproduces it
/// exactly, and a particle's step depends on where the midpoint rule samples it (so a newborn
/// particle, whose first sample is its source's velocity, moves differently from an older one).
constexpr float kA = 0.5f, kB = 1.f;
float w(float z) { return kA + kB * z; }

/// z after one midpoint step of length dt from z, first sample k1 (the field, or the source's
/// velocity for a newborn particle).
float midpointZ(float z, float k1, float dt) { return z + dt * w(z + 0.5f * dt * k1); }

constexpr float kDt = 0.01f;
constexpr float kSourceW = 2.f;  ///< the point sources' own upward velocity
/// float32 rounding of positions below 1 over a few steps, with margin.
constexpr float kTol = 1e-6f;

struct PauseRig {
  MacGrid3 velocity;
  ScalarGrid density{grid().resolution, 1.f};
  StreakTracer tracer;
  std::vector<glm::vec3> sources{{0.3f, 0.4f, 0.1f}, {0.6f, 0.5f, 0.2f}};
  PauseRig() : tracer(params(), grid(), sides()) {
    velocity.resize(grid().resolution);
    velocity.u().fill(0.f);
    velocity.v().fill(0.f);
    ScalarGrid& wf = velocity.w();
    for (int k = 0; k < wf.size().z; ++k)
      for (int j = 0; j < wf.size().y; ++j)
        for (int i = 0; i < wf.size().x; ++i) wf(i, j, k) = w(float(k) * grid().cellSize);
    tracer.addPointSources(sources, {0, 0}, {glm::vec3(0.f, 0.f, kSourceW), glm::vec3(0.f, 0.f, kSourceW)});
  }
  static StreakParams params() {
    StreakParams p;
    p.emissionPeriod = 2;
    p.interpolation = Interpolation::Linear;
    return p;
  }
  static std::array<Boundary, 6> sides() {
    std::array<Boundary, 6> s;
    s.fill(Boundary::Open);
    return s;
  }
  void step() { tracer.step(velocity, velocity, density, kDt); }
};

/// One step, checking that every particle there before moved by the midpoint rule (newborn: the
/// youngest row when `youngestNewborn`) and that `rowsAfter` rows are held afterwards.
void stepAndCheck(PauseRig& s, bool youngestNewborn, int rowsAfter, const char* what) {
  const StreakTracerState before = s.tracer.state();
  s.step();
  const StreakTracerState& after = s.tracer.state();
  ASSERT_EQ(after.emissions, rowsAfter) << what;
  const std::size_t n = s.sources.size();
  for (std::size_t m = 0; m < before.positions.size(); ++m) {
    const glm::vec3 x = before.positions[m];
    const bool newborn = youngestNewborn && m / n == std::size_t(before.emissions - 1);
    const float z = midpointZ(x.z, newborn ? kSourceW : w(x.z), kDt);
    EXPECT_NEAR(after.positions[m].z, z, kTol) << what << ", particle " << m;
    EXPECT_EQ(after.positions[m].x, x.x);
    EXPECT_EQ(after.positions[m].y, x.y);
  }
  // A new row, if any, sits at the sources.
  for (std::size_t m = before.positions.size(); m < after.positions.size(); ++m)
    EXPECT_EQ(after.positions[m], s.sources[m % n]) << what;
}

TEST(StreakTracerPause, PausedInstantsAddNoParticlesAndEmissionResumes) {
  PauseRig s;
  EXPECT_TRUE(s.tracer.emitting());
  // Emitting: rows at instants 0, 2, 4.
  stepAndCheck(s, true, 1, "step 1");
  stepAndCheck(s, false, 2, "step 2");
  stepAndCheck(s, true, 2, "step 3");
  stepAndCheck(s, false, 3, "step 4");
  // Paused over instants 6 and 8: the row of instant 4 is still newborn on step 5 (it was emitted
  // before the pause); after a skipped instant nothing is newborn.
  s.tracer.setEmitting(false);
  EXPECT_FALSE(s.tracer.emitting());
  stepAndCheck(s, true, 3, "paused step 5");
  stepAndCheck(s, false, 3, "paused step 6");
  stepAndCheck(s, false, 3, "paused step 7");
  stepAndCheck(s, false, 3, "paused step 8");
  EXPECT_EQ(s.tracer.snapshot().counts, std::vector<int>(2, 3));
  // Resumed: the next instant (10) emits, and that row is newborn on the step after it.
  s.tracer.setEmitting(true);
  stepAndCheck(s, false, 3, "step 9");
  stepAndCheck(s, false, 4, "step 10");
  stepAndCheck(s, true, 4, "step 11");
  stepAndCheck(s, false, 5, "step 12");
  EXPECT_EQ(s.tracer.particlesPerSource(), 5);  // floor(12 / 2) + 1 less the 2 skipped instants
  EXPECT_EQ(s.tracer.steps(), 12);

  // The gap (Figure 10): along each streakline the rows born either side of the pause (instants
  // 4 and 10) lie much further apart than rows born one period apart (4 and 2).
  const StreakFrame f = s.tracer.snapshot();
  ASSERT_EQ(f.counts, std::vector<int>(2, 5));
  for (std::size_t src = 0; src < 2; ++src) {
    const glm::vec3* p = &f.positions[src * 5];  // oldest first: instants 0, 2, 4, 10, 12
    const float regular = p[1].z - p[2].z, gap = p[2].z - p[3].z;
    EXPECT_GT(gap, 2.5f * regular) << "source " << src;
  }
}

TEST(StreakTracerPause, PausedFromTheStartKeepsOnlyTheFirstParticle) {
  PauseRig s;
  s.tracer.setEmitting(false);
  for (int n = 0; n < 6; ++n) s.step();
  // The first particle, emitted with the sources, is never skipped; it has moved on.
  EXPECT_EQ(s.tracer.snapshot().counts, std::vector<int>(2, 1));
  EXPECT_GT(s.tracer.state().positions[0].z, s.sources[0].z + 6.f * kDt * w(s.sources[0].z));
}

TEST(StreakTracerPause, StateValidationChecksTheYoungestEmission) {
  PauseRig s;
  for (int n = 0; n < 5; ++n) s.step();  // rows at 0, 2, 4
  StreakTracerState good = s.tracer.state();
  EXPECT_EQ(good.lastEmissionStep, 4);
  StreakTracerState bad = good;
  bad.lastEmissionStep = 3;  // not an emission instant
  EXPECT_THROW(s.tracer.setState(bad), std::invalid_argument);
  bad.lastEmissionStep = 6;  // after the steps seen
  EXPECT_THROW(s.tracer.setState(bad), std::invalid_argument);
  bad.lastEmissionStep = 2;  // 3 rows cannot end at instant 2
  EXPECT_THROW(s.tracer.setState(bad), std::invalid_argument);
  bad = good;
  bad.emitting = false;
  s.tracer.setState(bad);
  EXPECT_FALSE(s.tracer.emitting());
}

}  // namespace
}  // namespace plume
