/// \file toon_lanes_test.cpp
/// The lane kernels of the toon particle update equal their scalar references bit for bit: the
/// field samples (field_sampler.h, eight AVX2 lanes and four SSE lanes) against sampleLinear /
/// sampleVelocity (core/sampling.h), and the §2.3 ramps on four lanes (ramp_lanes.h) against
/// ToonParams. Exact equality is the claim: the particles must not depend on the CPU.

#include <gtest/gtest.h>

// The lane kernels are SSE4.1 code, inlined here: compile what follows for the build's baseline
// (x86-64-v2, the flags of plume_core), not the tests' default target.
#pragma GCC target("sse4.2")

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "core/sampling.h"
#include "tests/toon_plume.h"
#include "toon/field_sampler.h"
#include "toon/ramp_lanes.h"

namespace plume {
namespace {

bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

TEST(ToonFieldSampler, LanesEqualSampleLinearBitForBit) {
  const GridFrame g = testing::plumeGrid(6, 0.1f);  // 6 x 6 x 12 cells
  const ToonFields a = testing::plumeFields(g, 1.f), b = testing::plumeFields(g, 0.7f, -0.4f);
  const glm::ivec3 n = g.resolution;
  std::mt19937 rng(5);
  // Cell coordinates inside and up to two cells beyond every face (the samples clamp there).
  std::uniform_real_distribution<float> x(-2.f, float(n.x) + 1.f), z(-2.f, float(n.z) + 1.f);
  const ToonFieldSampler wide(n), narrow(n, /*wide=*/false);
  EXPECT_FALSE(narrow.wide());
  for (int group = 0; group < 200; ++group) {
    ToonLanes3 c;
    for (int l = 0; l < kToonLanes; ++l) {
      c.c[0][l] = x(rng);
      c.c[1][l] = x(rng);
      c.c[2][l] = z(rng);
    }
    if (group == 0) c.c[1][3] = float(n.y - 1);  // exactly on the last sample
    for (const float t : {0.f, 0.3f, 1.f}) {
      for (const ToonFieldSampler* s : {&wide, &narrow}) {
        ToonLanes3 v, u;
        alignas(32) float d[kToonLanes], temp[kToonLanes];
        s->velocity(a.velocity, b.velocity, t, c, v);
        s->fields(b, c, u, d, temp);
        for (int l = 0; l < kToonLanes; ++l) {
          const glm::vec3 p(c.c[0][l], c.c[1][l], c.c[2][l]);
          const glm::vec3 va = sampleVelocity(a.velocity, p), vb = sampleVelocity(b.velocity, p);
          const glm::vec3 ref = t <= 0.f ? va : (t >= 1.f ? vb : (1.f - t) * va + t * vb);
          for (int m = 0; m < 3; ++m) {
            ASSERT_TRUE(sameBits(v.c[m][l], ref[m]))
                << "velocity, wide " << s->wide() << " lane " << l;
            ASSERT_TRUE(sameBits(u.c[m][l], vb[m])) << "end velocity, lane " << l;
          }
          ASSERT_TRUE(sameBits(d[l], sampleLinear(b.density, p))) << "density, lane " << l;
          ASSERT_TRUE(sameBits(temp[l], sampleLinear(b.temperature, p))) << "temperature";
        }
      }
    }
  }
  // No temperature grid: it reads 0.
  ToonFields cold = b;
  cold.temperature = ScalarGrid();
  ToonLanes3 c{}, u;
  alignas(32) float d[kToonLanes], temp[kToonLanes];
  wide.fields(cold, c, u, d, temp);
  for (float v : temp) EXPECT_EQ(v, 0.f);
}

TEST(ToonFieldSampler, NanPositionsReadTheFirstSample) {
  const GridFrame g = testing::plumeGrid(4, 0.1f);
  const ToonFields f = testing::plumeFields(g);
  for (const bool w : {true, false}) {
    const ToonFieldSampler s(g.resolution, w);
    ToonLanes3 c{}, u;
    alignas(32) float d[kToonLanes], temp[kToonLanes];
    for (float& v : c.c[1]) v = std::nanf("");
    s.fields(f, c, u, d, temp);
    for (int l = 0; l < kToonLanes; ++l)
      EXPECT_TRUE(sameBits(d[l], sampleLinear(f.density, glm::vec3(0.f))));
  }
}

TEST(RampLanes4, EqualTheScalarRampsBitForBit) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::nanf("");
  const float values[] = {-1.f, 0.f, -0.f, 0.05f, 0.1f, 0.1000001f, 0.37f, 0.99999994f, 1.f,
                          1.3f, 7.f, inf,  -inf,  nan,  1e-30f,     3e38f, 0.5f,        0.25f};
  for (const auto driver :
       {ToonColorDriver::Density, ToonColorDriver::Temperature, ToonColorDriver::Speed}) {
    // The plume's settings with ramps that do not end on round numbers.
    ToonParams p = testing::plumeParams();
    p.rampDensityHigh = 0.9f;
    p.sizeLow = 0.013f;
    p.sizeHigh = 0.07f;
    p.maxSizeChange = 0.15f;
    p.colorDriver = driver;
    p.colorLow = 0.2f;
    p.colorHigh = 1.7f;
    const RampLanes4 lanes(p);
    const float step = p.maxSizeStep();
    for (float a : values)
      for (float b : values) {
        // Lanes: density a and b, temperature b, velocity (a, b, 0.5) where finite.
        const float d[4] = {a, b, a, b}, t[4] = {b, a, a, b};
        const float sx[4] = {a, b, b, 0.3f}, sy[4] = {b, a, 0.5f, a};
        __m128 vel[3] = {_mm_loadu_ps(sx), _mm_loadu_ps(sy), _mm_set1_ps(0.5f)};
        alignas(16) float target[4], color[4], unit[4], size[4];
        _mm_store_ps(target, lanes.targetSize(_mm_loadu_ps(d)));
        _mm_store_ps(color, lanes.color(_mm_loadu_ps(d), _mm_loadu_ps(t), vel));
        _mm_store_ps(unit, RampLanes4::unitRamp(_mm_loadu_ps(d), p.colorLow, p.colorHigh));
        // Sizes and targets in the ramp's range: the step toward a target from every size.
        const float s4[4] = {std::abs(a) < 1.f ? std::abs(a) * 0.07f : 0.f, 0.05f, 0.f, 0.07f};
        const float g4[4] = {0.02f, std::abs(b) < 1.f ? std::abs(b) * 0.07f : 0.f, 0.07f, 0.f};
        _mm_store_ps(size, lanes.sizeStep(_mm_loadu_ps(s4), _mm_loadu_ps(g4)));
        for (int l = 0; l < 4; ++l) {
          const float ramp = d[l] < p.deathDensity ? 0.f : p.rampSize(d[l]);
          EXPECT_TRUE(sameBits(target[l], std::isfinite(ramp) ? ramp : 0.f)) << d[l];
          const float speed = glm::length(glm::vec3(sx[l], sy[l], 0.5f));
          EXPECT_TRUE(sameBits(color[l], p.colorParameter(d[l], t[l], speed)))
              << d[l] << " " << t[l];
          EXPECT_TRUE(sameBits(unit[l], ToonParams::unitRamp(d[l], p.colorLow, p.colorHigh)));
          const float diff = g4[l] - s4[l];
          const float moved =
              std::abs(diff) <= step ? g4[l] : (diff > 0.f ? s4[l] + step : s4[l] - step);
          EXPECT_TRUE(sameBits(size[l], moved)) << s4[l] << " -> " << g4[l];
        }
      }
  }
}

TEST(RampLanes4, FiniteLanes) {
  const float v[4] = {1.f, std::numeric_limits<float>::infinity(), std::nanf(""), -3e38f};
  const int mask = _mm_movemask_ps(finiteLanes(_mm_loadu_ps(v)));
  EXPECT_EQ(mask, 0b1001);
}

}  // namespace
}  // namespace plume
