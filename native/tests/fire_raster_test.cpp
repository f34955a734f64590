/// \file fire_raster_test.cpp
/// Particle rasterization shared by flow-graph fire and flames (fields/fire_raster.h,
/// graph_fire_synthesis.txt §5.3): mass conservation, the flame map, one particle at a voxel
/// centre, determinism and the frame VDB.

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

std::string tempPath(const std::string& name) { return ::testing::TempDir() + "plume_fire_raster_" + name; }

struct Cloud {
  std::vector<glm::vec3> x;
  std::vector<float> r, t;
  FireParticleView view() const { return {x.data(), r.data(), t.data(), x.size()}; }
};

Cloud randomCloud(int count) {
  Cloud c;
  Rng rng(5);
  for (int n = 0; n < count; ++n) {
    c.x.emplace_back(0.3 + 0.4 * rng.uniform(), 0.2 + 0.5 * rng.uniform(), 0.1 + 0.8 * rng.uniform());
    c.r.push_back(float(rng.uniform()));
    c.t.push_back(float(5.0 * rng.uniform()));
  }
  return c;
}

double gridSum(const openvdb::FloatGrid& g) {
  double s = 0.0;
  for (auto it = g.cbeginValueOn(); it; ++it) s += double(*it);
  return s;
}

TEST(FireRaster, ConservesMassAndMapsFlame) {
  FireRasterParams p;
  p.voxelSize = 1.f / 32.f;
  const Cloud c = randomCloud(20000);
  const FireGrids g = rasterizeFire(c.view(), p);
  // Σ ρ_v Δx³ = Σ R_p V_p with V_p = (Δx/2)³.
  double mass = 0.0;
  for (float r : c.r) mass += double(r) * std::pow(0.5 * p.voxelSize, 3.0);
  const double h3 = std::pow(double(p.voxelSize), 3.0);
  EXPECT_NEAR(gridSum(*g.density) * h3, mass, 1e-5 * mass);
  // Temperatures are means of particle temperatures in [0, 5]; flame maps [1, 4] to [0, 1].
  for (auto it = g.temperature->cbeginValueOn(); it; ++it) {
    ASSERT_GE(*it, 0.f);
    ASSERT_LE(*it, 5.f + 1e-4f);
    const float f = g.flame->tree().getValue(it.getCoord());
    ASSERT_NEAR(f, std::min(1.f, std::max(0.f, (*it - 1.f) / 3.f)), 1e-6f);
  }
  EXPECT_EQ(g.density->getName(), "density");
  EXPECT_EQ(g.flame->getGridClass(), openvdb::GRID_FOG_VOLUME);
}

TEST(FireRaster, OneParticleAtAVoxelCentre) {
  FireRasterParams p;
  p.voxelSize = 0.1f;
  p.origin = glm::vec3(-1.f, 0.f, 0.f);
  p.particleVolume = 0.002f;
  // Voxel (3, 4, 5) is centred at origin + (3.5, 4.5, 5.5) Δx.
  const glm::vec3 x = p.origin + glm::vec3(3.5f, 4.5f, 5.5f) * p.voxelSize;
  const float r = 2.f, t = 3.f;
  const FireGrids g = rasterizeFire({&x, &r, &t, 1}, p);
  const openvdb::Coord ijk(3, 4, 5);
  EXPECT_NEAR(g.density->tree().getValue(ijk), r * p.particleVolume / 0.001f, 1e-4f);
  EXPECT_NEAR(g.temperature->tree().getValue(ijk), t, 1e-5f);  // weight 1: its own temperature
  EXPECT_NEAR(g.flame->tree().getValue(ijk), 2.f / 3.f, 1e-5f);
  // Its neighbours get the rest of the hat weight: nothing but float rounding here.
  EXPECT_NEAR(gridSum(*g.density), r * p.particleVolume / 0.001f, 1e-4f);
}

TEST(FireRaster, DeterministicAndWrittenAsAFrameVdb) {
  const Cloud c = randomCloud(30000);
  FireGrids g[2];
  for (int t = 0; t < 2; ++t) {
    FireRasterParams p;
    p.voxelSize = 1.f / 48.f;
    p.threads = t + 1;
    g[t] = rasterizeFire(c.view(), p);
  }
  for (auto pick : {&FireGrids::density, &FireGrids::temperature, &FireGrids::flame}) {
    const openvdb::FloatGrid& a = *(g[0].*pick);
    const openvdb::FloatGrid& b = *(g[1].*pick);
    ASSERT_EQ(a.activeVoxelCount(), b.activeVoxelCount());
    for (auto it = a.cbeginValueOn(); it; ++it) ASSERT_EQ(*it, b.tree().getValue(it.getCoord()));
  }
  const std::string path = tempPath("fire_0001.vdb");
  writeFireVdb(path, g[0], 1);
  auto names = vdbGridNames(path);
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"density", "flame", "temperature"}));
  const DenseGrid d = readVdbGrid(path, "density");
  EXPECT_NEAR(d.voxelSize, 1.f / 48.f, 1e-7f);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
}

TEST(FireRaster, VelocityGridIsTheParticlesMeanVelocityAndOnlyWhenGiven) {
  Cloud c = randomCloud(4000);
  FireRasterParams params;
  params.voxelSize = 0.05f;
  EXPECT_FALSE(rasterizeFire(c.view(), params).velocity);  // no velocities, no grid
  // u = (1, 0, 2) + 3 x: a smooth field; the voxel mean of its particles stays within the
  // kernel's reach (one voxel, Δx = 0.05: 3 Δx = 0.15) of u at the voxel centre.
  std::vector<glm::vec3> u;
  for (const glm::vec3& x : c.x) u.emplace_back(1.f + 3.f * x.x, 0.f, 2.f);
  FireParticleView view = c.view();
  view.velocities = u.data();
  const FireGrids g = rasterizeFire(view, params);
  ASSERT_TRUE(g.velocity);
  EXPECT_EQ(g.velocity->getName(), "velocity");
  int voxels = 0;
  for (auto it = g.velocity->cbeginValueOn(); it; ++it, ++voxels) {
    const openvdb::Vec3d centre = g.velocity->indexToWorld(it.getCoord());
    if (g.density->tree().getValue(it.getCoord()) <= 0.f) continue;
    EXPECT_NEAR((*it)[0], 1.0 + 3.0 * centre.x(), 0.16);
    EXPECT_NEAR((*it)[2], 2.0, 1e-5);
  }
  EXPECT_GT(voxels, 100);
}

}  // namespace
}  // namespace plume
