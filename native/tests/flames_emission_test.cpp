// Emission of structural flames ([Structural Flames] §5.1–5.3): blackbody colours, each
// particle's power (eq. 6 as a share of eq. 5's E), the colour normalization, the light's colour,
// and the emission / opacity grids.

#include "flames/blackbody.h"
#include "flames/flame_raster.h"
#include "flames/flame_shape.h"
#include "flames/spine.h"

#include <gtest/gtest.h>

#include <openvdb/openvdb.h>

#include <cmath>

namespace plume {
namespace {

constexpr double kPi = 3.14159265358979323846;

Flame uprightFlame(double length, double radius, double speed, std::uint32_t id = 1) {
  Flame f;
  f.id = id;
  f.radius = radius;
  for (int k = 0; k < 8; ++k) {
    SpinePoint p;
    p.x = {0.0, 0.0, length * k / 7.0};
    p.v = {0.0, 0.0, speed};
    p.age = length * k / 7.0 / speed;
    f.points.push_back(p);
  }
  return f;
}

/// A colour image of `height` rows: blue at the bottom row, yellow at the top, red elsewhere.
ColorImage threeBands() {
  ColorImage image;
  image.width = 2;
  image.height = 3;
  image.rgb = {0.1f, 0.2f, 1.0f, 0.1f, 0.2f, 1.0f,   // bottom: blue
               1.0f, 0.2f, 0.05f, 1.0f, 0.2f, 0.05f,  // middle: red
               1.0f, 0.9f, 0.3f, 1.0f, 0.9f, 0.3f};   // top: yellow
  return image;
}

double sum(const std::vector<float>& v) {
  double s = 0.0;
  for (float x : v) s += x;
  return s;
}

TEST(FlamesEmission, BlackbodyIsRedWhenCoolBluerWhenHotAndHasLuminanceOne) {
  // Below ~1,900 K the blue of Rec. 709 is negative (outside the gamut) and clipped to 0.
  double previous = 0.0;
  for (double t : {1000.0, 1500.0, 2000.0, 3000.0, 6500.0, 12000.0}) {
    const glm::vec3 c = blackbodyColor(t);
    EXPECT_NEAR(luminance(c), 1.0, 1e-5) << t;
    const double blueOverRed = c.z / c.x;
    if (t > 1900.0) EXPECT_GT(blueOverRed, previous) << t;  // §5.1: "hotter regions are bluer"
    previous = blueOverRed;
  }
  // 1500 K (a candle's soot, ~1,500–1,900 K) is deep orange; 6,500 K is close to D65 white.
  const glm::vec3 warm = blackbodyColor(1500.0), white = blackbodyColor(6500.0);
  EXPECT_GT(warm.x, 3.0 * warm.y);
  EXPECT_LT(warm.z, 0.05f * warm.x);
  EXPECT_NEAR(white.x / white.z, 1.0, 0.1);
  EXPECT_NEAR(white.y / white.z, 1.0, 0.1);
}

TEST(FlamesEmission, ParticlePowerSumsToEquation5ForAnyCount) {
  const Flame flame = uprightFlame(0.3, 0.03, 1.5);
  FlameCamera camera;
  camera.position = {0.0, -2.0, 0.3};
  for (int n : {1000, 10000, 100000}) {
    FlameShapeParams params;
    params.sampling.fixedCount = n;
    const FlameShaper shaper({FlameProfile::library(ProfileShape::Torch)}, params);
    const FlameShapeFrame frame = shaper.shape({flame}, 0.4, camera);
    // P_i = E_i · 4π((h/2)² + l²): Σ P_i → E (the same 1% as eq. 6's sum, see flames_shape_test).
    EXPECT_NEAR(sum(frame.particles.power) / frame.energy[0], 1.0, 0.01) << n;
    glm::dvec3 c, t, nn, b;
    SpineFrame(flame).frameAt(0.5, &c, &t, &nn, &b);
    const double h = SpineFrame(flame).length(), l = glm::length(c - camera.position);
    for (std::size_t m = 0; m < frame.particles.size(); m += 997)
      EXPECT_NEAR(frame.particles.power[m], frame.particles.incandescence[m] * 4.0 * kPi * (0.25 * h * h + l * l),
                  1e-5 * frame.particles.power[m]);
  }
}

TEST(FlamesEmission, ASeparatedPieceCarriesItsShareOfTheParentsEnergy) {
  // E = ½ k 0.3 m H_c 2 A_f r³ / h, m = |v_c| r², A_f = π r² (defaults k = 1, H_c = 15 MJ/kg).
  auto eq5 = [](double v, double r, double h) {
    return 0.5 * 0.3 * (v * r * r) * 15.0e6 * 2.0 * (kPi * r * r) * r * r * r / h;
  };
  FlameShapeParams params;
  params.sampling.fixedCount = 500;
  const FlameShaper shaper({FlameProfile::library(ProfileShape::Torch)}, params);
  FlameCamera camera;
  Flame attached = uprightFlame(0.12, 0.02, 1.0, 1), piece = uprightFlame(0.03, 0.02, 1.0, 2);
  piece.separated = true;
  piece.splitLength = 0.12;
  const FlameShapeFrame frame = shaper.shape({attached, piece}, 0.0, camera);
  const double h = SpineFrame(attached).length();
  EXPECT_NEAR(frame.energy[0] / eq5(1.0, 0.02, h), 1.0, 1e-9);
  // The piece: a quarter of the parent's length, a quarter of its energy (eq. 5's 1/h alone
  // would make it 4× the whole flame).
  EXPECT_NEAR(frame.energy[1] / (eq5(1.0, 0.02, 0.12) * SpineFrame(piece).length() / 0.12), 1.0, 1e-9);
  EXPECT_LT(frame.energy[1], frame.energy[0]);
}

TEST(FlamesEmission, AnAgeingPieceCoolsToTheTipsColour) {
  // A separated piece takes the top h / h_split of the image at birth and, as its life runs
  // out, moves to the image's top row: a young piece 0.4 of its flame's length spans mostly the
  // red band (g/r 0.2) under the yellow top (0.9); near its end it is all top-row yellow.
  FlameShapeParams params;
  params.sampling.fixedCount = 4000;
  params.flowNoise.amplitude = 0.0;
  params.kolmogorov.amplitude = 0.0;
  const FlameShaper shaper({FlameProfile::library(ProfileShape::Torch)}, params, {threeBands()});
  FlameCamera camera;
  auto meanGreenOverRed = [&](double age) {
    Flame piece = uprightFlame(0.03, 0.02, 1.0, 2);
    piece.separated = true;
    piece.splitLength = 0.075;
    piece.lifespan = 0.2;
    piece.age = age;
    const FlameParticles& p = shaper.shape({piece}, 0.0, camera).particles;
    double g = 0.0, r = 0.0;
    for (const glm::vec3& c : p.colors) g += c.y, r += c.x;
    return g / r;
  };
  const double young = meanGreenOverRed(0.0), old = meanGreenOverRed(0.198);
  EXPECT_LT(young, 0.7);        // measured 0.65: the red band blending into the top
  EXPECT_NEAR(old, 0.9, 0.02);  // all top row

  // With a cooling time A, its gas's age t_p (since it left the burning surface) cools it too:
  // the same young piece whose points are 1 s old, A = 0.1 s: e^(-10), all top row.
  FlameShapeParams cooled = params;
  cooled.coolingTime = 0.1;
  const FlameShaper aged({FlameProfile::library(ProfileShape::Torch)}, cooled, {threeBands()});
  Flame piece = uprightFlame(0.03, 0.02, 1.0, 2);
  piece.separated = true;
  piece.splitLength = 0.075;
  piece.lifespan = 0.2;
  for (SpinePoint& q : piece.points) q.age += 1.0;
  double g = 0.0, r = 0.0;
  for (const glm::vec3& c : aged.shape({piece}, 0.0, camera).particles.colors) g += c.y, r += c.x;
  EXPECT_NEAR(g / r, 0.9, 0.02);
  // ... and its light fades with its gas's mean age: e^(-mean t_p / A).
  Flame fresh = piece;
  double meanAge = 0.0;
  for (SpinePoint& q : fresh.points) q.age -= 1.0, meanAge += q.age + 1.0;
  meanAge /= double(fresh.points.size());
  EXPECT_NEAR(aged.shape({piece}, 0.0, camera).energy[0] / shaper.shape({piece}, 0.0, camera).energy[0],
              std::exp(-meanAge / 0.1), 1e-12);
  // An attached flame never cools: its colours are the image's, base to tip.
  Flame attached = uprightFlame(0.03, 0.02, 1.0, 2);
  for (SpinePoint& q : attached.points) q.age += 1.0;
  const FlameParticles a = aged.shape({attached}, 0.0, camera).particles;
  const FlameParticles b = FlameShaper({FlameProfile::library(ProfileShape::Torch)}, params, {threeBands()})
                               .shape({attached}, 0.0, camera).particles;
  EXPECT_EQ(a.colors, b.colors);
}

TEST(FlamesEmission, ColoursComeFromTheImageOnTheProfileWithMeanLuminanceOne) {
  FlameShapeParams params;
  params.sampling.fixedCount = 20000;
  params.flowNoise.amplitude = 0.0;
  params.kolmogorov.amplitude = 0.0;
  const FlameShaper shaper({FlameProfile::library(ProfileShape::Candle)}, params, {threeBands()});
  FlameCamera camera;
  camera.position = {0.0, -1.0, 0.05};
  const FlameShapeFrame frame = shaper.shape({uprightFlame(0.1, 0.01, 0.5)}, 0.0, camera);
  const FlameParticles& p = frame.particles;
  double weighted = 0.0, power = 0.0;
  int lowBlue = 0, low = 0, highYellow = 0, high = 0;
  for (std::size_t m = 0; m < p.size(); ++m) {
    weighted += p.power[m] * luminance(p.colors[m]);
    power += p.power[m];
    const double z = p.positions[m].z / 0.1;  // height fraction along the spine
    if (z < 0.1) ++low, lowBlue += p.colors[m].z > p.colors[m].x;
    if (z > 0.9 && z < 1.0) ++high, highYellow += p.colors[m].y > 0.5f * p.colors[m].x;
  }
  EXPECT_NEAR(weighted / power, 1.0, 1e-4);  // the image sets colour, eq. 5 the brightness
  ASSERT_GT(low, 100);
  ASSERT_GT(high, 20);
  EXPECT_GT(double(lowBlue) / low, 0.6);   // the bottom sixth of the image is blue
  EXPECT_GT(double(highYellow) / high, 0.6);
  // The light: the power-weighted mean colour at luminance 1, warm (red band dominates).
  const glm::vec3 light = frame.lights[0].color;
  EXPECT_NEAR(luminance(light), 1.0, 1e-4);
  EXPECT_GT(light.x, light.z);
}

TEST(FlamesEmission, NoImageGivesTheBlackbodyOfTheParticleTemperature) {
  FlameShapeParams params;
  params.sampling.fixedCount = 2000;
  params.temperature = 1800.0;
  const FlameShaper shaper({FlameProfile::library(ProfileShape::Torch)}, params);
  FlameCamera camera;
  camera.position = {0.0, -1.0, 0.05};
  const FlameShapeFrame frame = shaper.shape({uprightFlame(0.1, 0.01, 0.5)}, 0.0, camera);
  const glm::vec3 core = blackbodyColor(1800.0);
  int checked = 0;
  for (std::size_t m = 0; m < frame.particles.size(); ++m)
    if (frame.particles.density[m] == 1.f) {  // inside the profile: T = 1800 K
      const glm::vec3 c = frame.particles.colors[m];
      EXPECT_NEAR(c.z / c.x, core.z / core.x, 1e-4);
      ++checked;
    }
  EXPECT_GT(checked, 300);
}

TEST(FlamesEmission, EmissionGridHoldsTheLightUnitTimesThePowerAndOpacityTheSquaredDensity) {
  openvdb::initialize();
  FlameShapeParams params;
  params.sampling.fixedCount = 50000;
  const FlameShaper shaper({FlameProfile::library(ProfileShape::Candle)}, params);
  FlameCamera camera;
  camera.position = {0.0, -1.0, 0.05};
  const FlameShapeFrame frame = shaper.shape({uprightFlame(0.1, 0.02, 0.5)}, 0.0, camera);
  FlameRasterParams raster;
  raster.voxelSize = 0.004f;
  raster.emissionScale = 250.f;
  raster.opacity = 0.7f;
  const FlameGrids grids = rasterizeFlames(frame.particles, raster);
  double emitted = 0.0, core = 0.0;
  int coreVoxels = 0;
  for (auto it = grids.emission->cbeginValueOn(); it; ++it)
    emitted += double(luminance(glm::vec3((*it)[0], (*it)[1], (*it)[2])));
  for (auto it = grids.density->cbeginValueOn(); it; ++it) {
    const openvdb::Vec3d x = grids.density->indexToWorld(it.getCoord());
    // Near the axis where the candle is widest (s = 0.15…0.45, ρ < R/3): d = I.
    if (std::hypot(x.x(), x.y()) < 0.02 / 3.0 && x.z() > 0.015 && x.z() < 0.045) core += *it, ++coreVoxels;
  }
  const double cell = std::pow(double(raster.voxelSize), 3.0);
  // Conserving splats and colours of mean luminance 1: Σ lum(emission) Δx³ = U Σ P_i (float
  // sums over ~10⁴ voxels: 1e-4).
  EXPECT_NEAR(emitted * cell / (250.0 * sum(frame.particles.power)), 1.0, 1e-4);
  // The core is filled (d = I): the splatted Σ d_i m_i / Δx³ is ≈ d² = 1 there, times the
  // opacity. Each voxel holds ~20 particles (±22 %); the mean over the core's voxels is within 10 %.
  ASSERT_GT(coreVoxels, 10);
  EXPECT_NEAR(core / coreVoxels, 0.7, 0.07);
  EXPECT_EQ(grids.emission->getName(), "emission");
  EXPECT_EQ(grids.density->getName(), "density");
}

}  // namespace
}  // namespace plume
