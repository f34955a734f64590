/// \file flowgraph_pathlines_test.cpp
/// Flow-graph pathlines ([Graph Fire Synthesis] §4.2): RK4 integration (eq. 6) on fields with
/// known solutions, the seeds of a fuel cell and the pathline settings. Their files and the
/// synthesizer are in flowgraph_synth_test.cpp.

#include "core/parallel.h"
#include "core/rng.h"
#include "fields/fire_raster.h"
#include "flowgraph/pathline_integrator.h"
#include "flowgraph/pathline_recorder.h"
#include "flowgraph/synthesizer.h"
#include "fields/velocity_field.h"
#include "flowgraph/pathline_file.h"
#include "io/vdb_frame.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace plume {
namespace {

constexpr int kN = 16;
constexpr float kH = 1.f / kN;
const glm::vec3 kCentre(0.5f, 0.5f, 0.5f);

/// A MAC grid of kN³ cells of size kH at the origin holding u(x) = ω ẑ × (x - c): linear, so
/// trilinear sampling reproduces it exactly inside the grid.
MacGrid3 rotation(float omega) {
  MacGrid3 m{glm::ivec3(kN)};
  for (int a = 0; a < 2; ++a) {
    ScalarGrid& g = m.component(a);
    const glm::ivec3 n = g.size();
    for (int k = 0; k < n.z; ++k)
      for (int j = 0; j < n.y; ++j)
        for (int i = 0; i < n.x; ++i) {
          glm::vec3 x = (glm::vec3(i, j, k) + glm::vec3(0.5f)) * kH;
          x[a] -= 0.5f * kH;  // faces of axis a sit half a cell lower
          g(i, j, k) = a == 0 ? -omega * (x.y - kCentre.y) : omega * (x.x - kCentre.x);
        }
  }
  return m;
}

MacGrid3 uniform(glm::vec3 u) {
  MacGrid3 m{glm::ivec3(kN)};
  for (int a = 0; a < 3; ++a) m.component(a).fill(u[a]);
  return m;
}

glm::vec3 rotated(glm::vec3 x, float angle) {
  const glm::vec3 d = x - kCentre;
  return kCentre + glm::vec3(std::cos(angle) * d.x - std::sin(angle) * d.y,
                             std::sin(angle) * d.x + std::cos(angle) * d.y, d.z);
}

TEST(PathlineIntegrator, ExactOnAFieldLinearInTime) {
  // u(t) = a + θ (b - a) everywhere: x(θ) = x0 + dt (θ a + θ²/2 (b - a)), a quadratic RK4 is
  // exact for.
  const glm::vec3 a(0.3f, -0.2f, 0.5f), b(-0.1f, 0.4f, 0.9f);
  const MacGrid3 ga = uniform(a), gb = uniform(b);
  const SubstepVelocity u(ga, gb, kH, glm::vec3(0.f));
  const glm::vec3 x0(0.4f, 0.5f, 0.3f);
  const float dt = 0.2f;
  const glm::vec3 x = integrateRk4(u, x0, 0.25f, 0.75f, dt, 1);
  const glm::vec3 exact = x0 + dt * (0.5f * a + 0.5f * (0.75f * 0.75f - 0.25f * 0.25f) * (b - a));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(x[c], exact[c], 1e-6f);
}

TEST(PathlineIntegrator, FourthOrderOnAnUnsteadyRotation) {
  // ω blends from ω0 at the substep's start to ω1 at its end; rotations about one axis commute,
  // so the exact pathline turns by ∫ω dt = dt (ω0 + ω1) / 2.
  const float w0 = 2.f, w1 = 4.f, dt = 1.f;
  const MacGrid3 g0 = rotation(w0), g1 = rotation(w1);
  const SubstepVelocity u(g0, g1, kH, glm::vec3(0.f));
  const glm::vec3 x0(0.75f, 0.5f, 0.5f);
  const glm::vec3 exact = rotated(x0, dt * 0.5f * (w0 + w1));
  double error[3];
  const int steps[3] = {4, 8, 16};
  for (int n = 0; n < 3; ++n) error[n] = glm::length(integrateRk4(u, x0, 0.f, 1.f, dt, steps[n]) - exact);
  const double order1 = std::log2(error[0] / error[1]), order2 = std::log2(error[1] / error[2]);
  std::cout << "RK4 errors " << error[0] << " " << error[1] << " " << error[2] << ", orders "
            << order1 << " " << order2 << "\n";
  EXPECT_GE(order1, 3.5);
  EXPECT_GE(order2, 3.5);
  EXPECT_LT(error[2], 1e-4);
}

TEST(PathlineIntegrator, StepCountFollowsTheSpeed) {
  // 3 cells in one substep need 3 steps; advancePathline() then matches integrateRk4(3).
  const MacGrid3 g = rotation(3.f);
  const SubstepVelocity u(g, g, kH, glm::vec3(0.f));
  const glm::vec3 x0(0.75f, 0.5f, 0.5f);  // speed 0.75 m/s = 12 cells/s
  const float dt = 0.25f;                  // 3 cells
  const glm::vec3 a = advancePathline(u, x0, 0.f, 1.f, dt, kH);
  const glm::vec3 b = integrateRk4(u, x0, 0.f, 1.f, dt, 3);
  EXPECT_EQ(a, b);
  EXPECT_NEAR(glm::length(a - rotated(x0, 0.75f)), 0.f, 2e-4f);
}

TEST(PathlineSeeds, EightPerCellAtHalfCellSpacing) {
  CellSet cells;
  cells.cells = {5, 3, 5};  // duplicates and order do not matter
  const auto seeds = pathlineSeeds(cells, glm::ivec3(4, 2, 2), 0.5f, glm::vec3(1.f, 0.f, 0.f));
  ASSERT_EQ(seeds.size(), 16u);
  // Cell 3 = (3, 0, 0) first, x fastest: (3.25, 0.25, 0.25) Δx, then (3.75, 0.25, 0.25) Δx.
  EXPECT_EQ(seeds[0], glm::vec3(1.f + 3.25f * 0.5f, 0.125f, 0.125f));
  EXPECT_EQ(seeds[1], glm::vec3(1.f + 3.75f * 0.5f, 0.125f, 0.125f));
  EXPECT_EQ(seeds[2], glm::vec3(1.f + 3.25f * 0.5f, 0.375f, 0.125f));
  EXPECT_EQ(seeds[8], glm::vec3(1.f + 1.25f * 0.5f, 0.625f, 0.125f));  // cell 5 = (1, 1, 0)
  EXPECT_THROW(pathlineSeeds(CellSet{}, glm::ivec3(4), 1.f, glm::vec3(0.f)), std::invalid_argument);
  cells.cells = {64};
  EXPECT_THROW(pathlineSeeds(cells, glm::ivec3(4), 1.f, glm::vec3(0.f)), std::invalid_argument);
}

TEST(PathlineParams, ValidateNamesTheSetting) {
  auto message = [](const PathlineParams& p, float frameDt) {
    try {
      p.validate();
      p.samples(frameDt);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  PathlineParams p;
  EXPECT_EQ(p.samples(1.f / 24.f), 48);  // 1 s at 2 nodes per frame
  p.nodesPerFrame = 0;
  EXPECT_NE(message(p, 1.f / 24.f).find("nodes_per_frame"), std::string::npos);
  p = PathlineParams();
  p.lifetime = -1.f;
  EXPECT_NE(message(p, 1.f / 24.f).find("lifetime"), std::string::npos);
  p.lifetime = 0.01f;  // less than two node steps
  EXPECT_NE(message(p, 1.f / 24.f).find("lifetime"), std::string::npos);
}

}  // namespace
}  // namespace plume
