/// \file toon_render_test.cpp
/// The rendering side of toon smoke ([Cartoon Smoke] §2.2-2.3): the depth-differences filter
/// against the per-pixel formula, stencil orientation and stretch (Figure 4), and the volume
/// frames that drive the particles.

#include "io/mantaflow_cache.h"
#include "toon/toon_volume.h"
#include "toon/billboard.h"
#include "toon/depth_differences.h"

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <filesystem>
#include <random>
#include <stdexcept>
#include "tests/temp_path.h"

namespace plume {
namespace {

/// §2.2 literally, one pixel at a time: the four one-sided differences over Δ against γ,
/// missing neighbours skipped, background pixels never outlined when ignored.
std::vector<std::uint8_t> bruteForce(const std::vector<float>& z, int w, int h,
                                     const DepthDifferenceParams& p) {
  std::vector<std::uint8_t> out(z.size(), 0);
  auto at = [&](int i, int j) { return z[std::size_t(j) * w + i]; };
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      if (p.ignoreBackground && !(at(i, j) < p.far)) continue;
      bool edge = false;
      if (i + 1 < w) edge |= std::abs(at(i + 1, j) - at(i, j)) / p.dx > p.gamma;
      if (i > 0) edge |= std::abs(at(i, j) - at(i - 1, j)) / p.dx > p.gamma;
      if (j + 1 < h) edge |= std::abs(at(i, j + 1) - at(i, j)) / p.dy > p.gamma;
      if (j > 0) edge |= std::abs(at(i, j) - at(i, j - 1)) / p.dy > p.gamma;
      out[std::size_t(j) * w + i] = edge;
    }
  return out;
}

std::vector<std::uint8_t> filtered(const std::vector<float>& z, int w, int h,
                                   const DepthDifferenceParams& p) {
  std::vector<std::uint8_t> out(z.size(), 7);
  depthDifferences(z.data(), w, h, p, out.data());
  return out;
}

/// Random depths in [1, 3] with about a fifth of the pixels background (+inf or 1e10).
std::vector<float> randomImage(int w, int h, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<float> z(std::size_t(w) * h);
  for (float& v : z) {
    const float r = u(rng);
    v = r < 0.1f ? INFINITY : (r < 0.2f ? 1e10f : 1.f + 2.f * u(rng));
  }
  return z;
}

/// Blocks of constant depth (stencils seen flat on): steps only at block borders.
std::vector<float> stepImage(int w, int h) {
  std::vector<float> z(std::size_t(w) * h);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i)
      z[std::size_t(j) * w + i] = ((i / 7 + j / 5) % 3 == 0) ? INFINITY : 1.f + 0.25f * float((i / 7) % 4 + (j / 5) % 2);
  return z;
}

TEST(DepthDifferences, MatchesThePerPixelFormula) {
  const std::vector<std::pair<int, int>> sizes = {{1, 1}, {1, 9}, {9, 1}, {2, 2}, {97, 70}, {300, 67}};
  for (const auto& [w, h] : sizes)
    for (float dx : {1.f, 0.37f, 2.f})
      for (float gamma : {0.f, 0.3f, 1.1f})
        for (bool ignore : {false, true})
          for (int image = 0; image < 2; ++image) {
            DepthDifferenceParams p;
            p.gamma = gamma;
            p.dx = dx;
            p.dy = dx == 1.f ? 0.61f : 1.f / dx;
            p.ignoreBackground = ignore;
            p.far = image ? 1e9f : INFINITY;
            const std::vector<float> z = image ? stepImage(w, h) : randomImage(w, h, unsigned(w * h));
            ASSERT_EQ(filtered(z, w, h, p), bruteForce(z, w, h, p))
                << w << "x" << h << " dx " << dx << " gamma " << gamma << " ignore " << ignore;
          }
}

TEST(DepthDifferences, OutlinesAStepOnBothSidesOrOnTheForegroundOnly) {
  // Left half at depth 1, right half background: with the background ignored only the
  // foreground column next to the step is outlined, otherwise both columns beside it.
  const int w = 8, h = 4;
  std::vector<float> z(std::size_t(w) * h, 1.f);
  for (int j = 0; j < h; ++j)
    for (int i = 4; i < w; ++i) z[std::size_t(j) * w + i] = INFINITY;
  DepthDifferenceParams p;
  for (bool ignore : {false, true}) {
    p.ignoreBackground = ignore;
    const auto m = filtered(z, w, h, p);
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w; ++i)
        EXPECT_EQ(m[std::size_t(j) * w + i], (i == 3 || (!ignore && i == 4)) ? 1 : 0) << i << "," << j;
  }
}

TEST(DepthDifferences, BadSettingsNameTheSetting) {
  std::vector<float> z(4, 1.f);
  std::vector<std::uint8_t> out(4);
  DepthDifferenceParams p;
  p.gamma = -1.f;
  EXPECT_THROW(depthDifferences(z.data(), 2, 2, p, out.data()), std::invalid_argument);
  p = {};
  p.dx = 0.f;
  try {
    depthDifferences(z.data(), 2, 2, p, out.data());
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("dx"), std::string::npos);
  }
}

/// A camera turned arbitrarily (30° about z, then 70° about its x) at (1, -4, 2).
ToonCamera turnedCamera(bool perspective) {
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), glm::dvec3(1.0, -4.0, 2.0));
  m = glm::rotate(m, glm::radians(30.0), glm::dvec3(0, 0, 1));
  m = glm::rotate(m, glm::radians(70.0), glm::dvec3(1, 0, 0));
  return ToonCamera{m, perspective};
}

TEST(Billboards, AngleFollowsTheProjectedVelocity) {
  for (bool perspective : {false, true}) {
    const ToonCamera cam = turnedCamera(perspective);
    const glm::vec3 right(cam.matrixWorld[0]), up(cam.matrixWorld[1]), back(cam.matrixWorld[2]);
    const glm::vec3 loc(cam.matrixWorld[3]);
    // In front of the camera, off its axis.
    const glm::vec3 p = loc - 5.f * back + 0.7f * right - 0.4f * up;
    const Billboards b = computeBillboards(cam, {p, p, p, p}, {2.f * right, 3.f * up, -right + up, 0.f * up}, 0.5f);
    EXPECT_NEAR(b.angle[0], 0.f, 1e-6f);
    EXPECT_NEAR(b.angle[1], 1.5707963f, 1e-6f);
    EXPECT_NEAR(b.angle[2], 3.f * 0.78539816f, 1e-6f);
    EXPECT_NEAR(b.stretch[0], 1.f + 0.5f * 2.f, 1e-5f);  // stretch = 1 + k |v_screen|
    EXPECT_NEAR(b.stretch[1], 1.f + 0.5f * 3.f, 1e-5f);
    EXPECT_EQ(b.angle[3], 0.f);  // no motion: no rotation, no stretch
    EXPECT_EQ(b.stretch[3], 1.f);
    EXPECT_NEAR(glm::length(b.axis[1] - up), 0.f, 1e-5f);
  }
}

TEST(Billboards, MotionTowardThePerspectiveCameraSpreadsFromTheCentre) {
  // At camera-space (1, 0, -5) moving toward the camera at 1 m/s, the projection x / -z grows:
  // v_screen = (v_x - x v_z / z, ...) = (0.2, 0) m/s. Orthographic, the same motion is invisible.
  const ToonCamera persp = turnedCamera(true), ortho = turnedCamera(false);
  const glm::vec3 right(persp.matrixWorld[0]), back(persp.matrixWorld[2]), loc(persp.matrixWorld[3]);
  const glm::vec3 p = loc - 5.f * back + right;
  const Billboards b = computeBillboards(persp, {p}, {back}, 1.f);
  EXPECT_NEAR(b.angle[0], 0.f, 1e-6f);
  EXPECT_NEAR(b.stretch[0], 1.2f, 1e-5f);
  const Billboards o = computeBillboards(ortho, {p}, {back}, 1.f);
  EXPECT_NEAR(o.stretch[0], 1.f, 1e-6f);
}

TEST(Billboards, BadInputsThrow) {
  ToonCamera cam = turnedCamera(true);
  EXPECT_THROW(computeBillboards(cam, {glm::vec3(0.f)}, {}, 1.f), std::invalid_argument);
  EXPECT_THROW(computeBillboards(cam, {}, {}, -1.f), std::invalid_argument);
  cam.matrixWorld[0] = glm::dvec4(0.0);
  EXPECT_THROW(computeBillboards(cam, {}, {}, 1.f), std::invalid_argument);
}

TEST(ToonVolume, ReadsAPlumeVolumeFrameOntoTheGrid) {
  // A volume as Plume writes it (io/mantaflow_cache writeMantaflowVolume: density and the
  // cell-centred velocity where there is smoke) on a domain of 6x5x4 cells of 0.2 m.
  const MantaflowGrid mg{glm::ivec3(6, 5, 4), glm::vec3(-1.f, 0.5f, 2.f), glm::vec3(0.2f)};
  MantaflowFrame frame = MantaflowFrame::empty(mg.resolution);
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 5; ++j)
      for (int i = 1; i < 6; ++i) frame.density(i, j, k) = 0.1f * float(i + j + k);
  frame.velocity.u().fill(0.5f);  // uniform: every face velocity inside the smoke is 0.5
  frame.velocity.w().fill(-0.25f);
  const std::string path = plume::test::tempPath("toon_volume.vdb");
  writeMantaflowVolume(path, frame, mg, 3);
  const GridFrame g{mg.resolution, 0.2f, mg.origin, 1.f / 24.f};
  const ToonFields f = readToonFields(path, g);
  ASSERT_EQ(f.density.size(), g.resolution);
  EXPECT_EQ(f.temperature.count(), 0u);  // not written: reads as absent
  for (std::size_t m = 0; m < f.density.count(); ++m) EXPECT_FLOAT_EQ(f.density[m], frame.density[m]);
  // Faces between smoke cells hold the velocity; the faces of the smoke-free column i = 0 take
  // the one smoke cell beside them (face 1) or none (face 0).
  EXPECT_FLOAT_EQ(f.velocity.u()(3, 2, 1), 0.5f);
  EXPECT_FLOAT_EQ(f.velocity.u()(1, 2, 1), 0.5f);
  EXPECT_FLOAT_EQ(f.velocity.u()(0, 2, 1), 0.f);
  EXPECT_FLOAT_EQ(f.velocity.w()(3, 2, 2), -0.25f);
  EXPECT_FLOAT_EQ(f.velocity.v()(3, 2, 2), 0.f);
  // Another domain placement or cell size is refused.
  EXPECT_THROW(readToonFields(path, GridFrame{mg.resolution, 0.25f, mg.origin, 1.f}), std::runtime_error);
  EXPECT_THROW(readToonFields(path, GridFrame{mg.resolution, 0.2f, glm::vec3(0.f), 1.f}), std::runtime_error);
  EXPECT_THROW(readToonFields(path, GridFrame{glm::ivec3(3), 0.2f, mg.origin, 1.f}), std::runtime_error);
  EXPECT_THROW(readToonFields(path + ".missing", g), std::runtime_error);
}

TEST(ToonVolume, ResamplesNonCubicMantaflowCellsOntoACubicGrid) {
  // A traced Mantaflow frame: 8x5x4 cells of 0.1 x 0.16 x 0.2 m (not cubic) holding a density
  // linear in world position and a uniform velocity; read onto cubic cells of 0.1 m over the
  // same 0.8 x 0.8 x 0.8 m box. Trilinear interpolation is exact for a linear field, so cells
  // whose centre lies between voxel centres get the linear value to float rounding.
  const MantaflowGrid mg{glm::ivec3(8, 5, 4), glm::vec3(-1.f, 0.5f, 2.f), glm::vec3(0.1f, 0.16f, 0.2f)};
  const auto linear = [&](glm::vec3 w) { return 1.f + 0.5f * (w.x - mg.origin.x) + 2.f * (w.y - mg.origin.y) +
                                                 0.25f * (w.z - mg.origin.z); };
  MantaflowFrame frame = MantaflowFrame::empty(mg.resolution);
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 8; ++i) frame.density(i, j, k) = linear(mg.indexToWorld(glm::vec3(i, j, k) + 0.5f));
  frame.velocity.u().fill(0.5f);
  frame.velocity.w().fill(-0.25f);
  const std::string path = plume::test::tempPath("toon_resample.vdb");
  writeMantaflowVolume(path, frame, mg, 1);
  const GridFrame g{glm::ivec3(8), 0.1f, mg.origin, 1.f / 24.f};
  EXPECT_THROW(readToonFields(path, g), std::runtime_error);  // the exact reader refuses them
  const ToonFields f = resampleToonFields(path, g);
  ASSERT_EQ(f.density.size(), g.resolution);
  int checked = 0;
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 8; ++i) {
        const glm::vec3 w = mg.origin + (glm::vec3(i, j, k) + 0.5f) * 0.1f;
        const glm::vec3 q = mg.worldToIndex(w) - 0.5f;  // voxel coordinates in the file
        if (glm::any(glm::lessThan(q, glm::vec3(0.f))) ||
            glm::any(glm::greaterThan(q, glm::vec3(mg.resolution - 1))))
          continue;
        EXPECT_NEAR(f.density(i, j, k), linear(w), 1e-5f) << i << " " << j << " " << k;
        // Every voxel holds the uniform velocity: interior faces read it exactly.
        EXPECT_NEAR(f.velocity.u()(i, j, k), 0.5f, 1e-6f);
        EXPECT_NEAR(f.velocity.w()(i, j, k), -0.25f, 1e-6f);
        EXPECT_NEAR(f.velocity.v()(i, j, k), 0.f, 1e-6f);
        ++checked;
      }
  EXPECT_GT(checked, 100);
  // The same frame on a grid that does not contain its voxels is refused.
  EXPECT_THROW(resampleToonFields(path, GridFrame{glm::ivec3(4), 0.1f, mg.origin, 1.f}), std::runtime_error);
}

}  // namespace
}  // namespace plume
