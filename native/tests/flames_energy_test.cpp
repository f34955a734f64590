// Eq. 5 of [Structural Flames] §5.2 checked against the printed formula itself: flames whose
// spines have known control-point velocities v_c, radius r and length h go through the
// FlameShaper, and its per-flame energy is compared with E = ½ k · 0.3 m · H_c · 2 A_f r³ / h,
// m = |v_c| r², written out here as literal arithmetic (not by calling flameEnergy()).
#include "flames/flame_shape.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace plume {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// A straight flame of n points from `base` up (z) over `height`; every point moves at `v`.
Flame straightFlame(glm::dvec3 base, double height, double radius, glm::dvec3 v, std::uint32_t id) {
  Flame f;
  f.id = id;
  f.radius = radius;
  const int n = 9;
  for (int k = 0; k < n; ++k) {
    SpinePoint p;
    p.x = base + glm::dvec3(0.0, 0.0, height * k / (n - 1));
    p.v = v;
    p.age = 0.01 * k;
    f.points.push_back(p);
  }
  return f;
}

FlameShaper shaperFor(double k, double heat, double fuelArea) {
  FlameShapeParams p;
  p.sampling.fixedCount = 64;  // the energy does not depend on the samples
  p.merging = false;
  p.incandescence.k = k;
  p.incandescence.heatOfCombustion = heat;
  p.incandescence.fuelArea = fuelArea;
  return FlameShaper({FlameProfile::library(ProfileShape::Torch)}, p);
}

FlameCamera camera() {
  FlameCamera c;
  c.position = {0.0, -3.0, 0.2};
  return c;
}

struct Case {
  double r, h;     // m
  glm::dvec3 v;    // v_c, m/s
  double heat;     // H_c, J/kg
  double area;     // A_f, m² (0: π r²)
  double k;
};

TEST(FlameEnergy, Equation5AsPrinted) {
  const Case cases[] = {
      {0.006, 0.04, {0.0, 0.0, 0.35}, 42.0e6, 0.0, 1.0},        // a candle: A_f = π r²
      {0.02, 0.15, {0.3, 0.0, 0.8}, 15.0e6, 0.0, 1.0},          // a torch flame, leaning
      {0.02, 0.15, {0.3, 0.0, 0.8}, 15.0e6, 2.0e-3, 1.0},       // the same with A_f given
      {0.12, 0.9, {0.5, -0.2, 1.6}, 48.0e6, 0.05, 2.5},          // a campfire tongue, gasoline
      {0.03, 0.25, {0.0, 0.0, 1.2}, 15.0e6, 0.0, 0.01},         // a small visual k
  };
  for (const Case& c : cases) {
    const FlameShaper shaper = shaperFor(c.k, c.heat, c.area);
    const FlameShapeFrame frame = shaper.shape({straightFlame({0.0, 0.0, 0.0}, c.h, c.r, c.v, 1)}, 0.0, camera());
    // By hand: m = |v_c| r², A_f (π r² when 0), E = ½ k · 0.3 m · H_c · 2 A_f r³ / h.
    const double speed = std::sqrt(c.v.x * c.v.x + c.v.y * c.v.y + c.v.z * c.v.z);
    const double m = speed * c.r * c.r;
    const double area = c.area > 0.0 ? c.area : kPi * c.r * c.r;
    const double expected = 0.5 * c.k * 0.3 * m * c.heat * 2.0 * area * c.r * c.r * c.r / c.h;
    ASSERT_EQ(frame.energy.size(), 1u);
    EXPECT_NEAR(frame.energy[0], expected, 1e-9 * expected) << "r " << c.r << ", h " << c.h << ", A_f " << c.area;
    ASSERT_EQ(frame.lights.size(), 1u);  // §5.2: the flame's light carries the same E
    EXPECT_NEAR(frame.lights[0].energy, expected, 1e-9 * expected);
  }
}

TEST(FlameEnergy, ScalesWithIntensityAndInverselyWithHeight) {
  // Two flames in one frame, equal r and v_c, the second twice as tall: E ∝ 1/h halves. A third
  // of intensity 3 (the spread maps' scale, §6.2) has 3 E.
  const FlameShaper shaper = shaperFor(1.0, 15.0e6, 0.0);
  const glm::dvec3 v(0.1, 0.0, 0.9);
  std::vector<Flame> flames = {straightFlame({0.0, 0.0, 0.0}, 0.1, 0.02, v, 1),
                               straightFlame({1.0, 0.0, 0.0}, 0.2, 0.02, v, 2),
                               straightFlame({2.0, 0.0, 0.0}, 0.1, 0.02, v, 3)};
  flames[2].intensity = 3.0;
  const FlameShapeFrame frame = shaper.shape(flames, 0.0, camera());
  ASSERT_EQ(frame.energy.size(), 3u);
  EXPECT_GT(frame.energy[0], 0.0);
  EXPECT_NEAR(frame.energy[1] / frame.energy[0], 0.5, 1e-12);
  EXPECT_NEAR(frame.energy[2] / frame.energy[0], 3.0, 1e-12);
}

TEST(FlameEnergy, BrightnessScalesEnergyNotOpacity) {
  // A source's Intensity in stops (Flame::brightness = 2^stops) scales E, so the flame's
  // emission and its light, and leaves its particles' density and mass (the opacity of §5.3)
  // alone.
  const FlameShaper shaper = shaperFor(1.0, 15.0e6, 0.0);
  const Flame bright = straightFlame({0.0, 0.0, 0.0}, 0.1, 0.02, {0.0, 0.0, 0.6}, 1);
  Flame dim = bright;
  dim.brightness = 0.125;  // -3 stops
  const FlameShapeFrame a = shaper.shape({bright}, 0.0, camera());
  const FlameShapeFrame b = shaper.shape({dim}, 0.0, camera());
  EXPECT_NEAR(b.energy[0] / a.energy[0], 0.125, 1e-12);
  EXPECT_NEAR(b.lights[0].energy / a.lights[0].energy, 0.125, 1e-12);
  EXPECT_EQ(a.particles.density, b.particles.density);
  EXPECT_EQ(a.particles.mass, b.particles.mass);
  EXPECT_EQ(a.particles.positions, b.particles.positions);
}

TEST(FlameEnergy, SeparatedPieceFadesAndThins) {
  // A separated piece a third of its flame's length is a slim flame, not a ball of the parent's
  // width (its widest radius × √(h / h_split)), and as its life runs out it dims (E × life
  // left) and thins (× √life left) to a wisp.
  FlameShapeParams params;
  params.sampling.fixedCount = 4096;  // the RMS width to well under 1 %
  params.merging = false;
  params.flowNoise.amplitude = 0.0;  // the width is the profile's alone
  params.kolmogorov.amplitude = 0.0;
  const FlameShaper shaper({FlameProfile::library(ProfileShape::Torch)}, params);
  const glm::dvec3 v(0.0, 0.0, 0.6);
  auto piece = [&](double age) {
    Flame f = straightFlame({0.0, 0.0, 0.0}, 0.05, 0.02, v, 1);
    f.separated = true;
    f.splitLength = 0.15;
    f.lifespan = 0.2;
    f.age = age;
    return f;
  };
  auto width = [](const FlameShapeFrame& frame) {  // RMS distance of the particles from the spine
    double sum = 0.0;
    for (const glm::vec3& x : frame.particles.positions) sum += double(x.x) * x.x + double(x.y) * x.y;
    return std::sqrt(sum / double(frame.particles.size()));
  };
  const FlameShapeFrame full = shaper.shape({straightFlame({0.0, 0.0, 0.0}, 0.05, 0.02, v, 1)}, 0.0, camera());
  const FlameShapeFrame young = shaper.shape({piece(0.0)}, 0.0, camera());
  const FlameShapeFrame old = shaper.shape({piece(0.15)}, 0.0, camera());  // a quarter left
  EXPECT_NEAR(old.energy[0] / young.energy[0], 0.25, 1e-12);
  EXPECT_NEAR(width(young) / width(full), std::sqrt(0.05 / 0.15), 0.01);
  EXPECT_NEAR(width(old) / width(young), 0.5, 0.01);
}

TEST(FlameEnergy, MeanControlPointVelocity) {
  // v_c is the mean velocity of the control points: 9 points moving at 0.2 and 1.0 m/s
  // alternately (five at 0.2, four at 1.0: mean 5/9 m/s) give the E of a flame moving at 5/9 m/s
  // everywhere.
  const FlameShaper shaper = shaperFor(1.0, 15.0e6, 0.0);
  Flame mixed = straightFlame({0.0, 0.0, 0.0}, 0.12, 0.02, {0.0, 0.0, 0.0}, 1);
  ASSERT_EQ(mixed.points.size(), 9u);
  for (std::size_t k = 0; k < mixed.points.size(); ++k) mixed.points[k].v = {0.0, 0.0, k % 2 ? 1.0 : 0.2};
  const Flame uniform = straightFlame({0.0, 0.0, 0.0}, 0.12, 0.02, {0.0, 0.0, 5.0 / 9.0}, 1);
  const double a = shaper.shape({mixed}, 0.0, camera()).energy[0];
  const double b = shaper.shape({uniform}, 0.0, camera()).energy[0];
  EXPECT_NEAR(a, b, 1e-9 * b);
}

}  // namespace
}  // namespace plume
