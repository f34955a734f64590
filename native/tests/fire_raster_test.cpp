/// \file fire_raster_test.cpp
/// Particle rasterization shared by flow-graph fire and flames (fields/fire_raster.h,
/// [Graph Fire Synthesis] §5.3): mass conservation, the flame map, one particle at a voxel
/// centre, splats sized by the particle spacing (no gaps between sparse particles),
/// determinism at any thread count and the frame VDB.

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
#include "tests/temp_path.h"

namespace fs = std::filesystem;

namespace plume {
namespace {

std::string tempPath(const std::string& name) { return plume::test::tempPath("fire_raster_" + name); }

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
  p.spacingScale = 0.f;  // the trilinear hat of one voxel
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

/// Particles of density 1, temperature 2 on a lattice of spacing 4 voxels: voxel centres
/// (4 i + 1, 4 j + 1, 4 k + 1), i, j, k < 8, so that every coarse cell of the spacing estimate
/// (C = 4 Δx, fields/splat_radius.h) holds exactly one.
Cloud sparseLattice(float h) {
  Cloud c;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j)
      for (int k = 0; k < 8; ++k) {
        c.x.push_back(glm::vec3(4 * i + 1.5f, 4 * j + 1.5f, 4 * k + 1.5f) * h);
        c.r.push_back(1.f);
        c.t.push_back(2.f);
      }
  return c;
}

TEST(FireRaster, SparseParticlesLeaveNoGapsAndConserveMass) {
  FireRasterParams p;
  p.voxelSize = 0.1f;
  const Cloud c = sparseLattice(p.voxelSize);
  const FireGrids g = rasterizeFire(c.view(), p);
  // Σ ρ_v Δx³ = Σ R_p V_p, V_p = (Δx/2)³, whatever the kernels' radii.
  const double mass = double(c.x.size()) * std::pow(0.5 * p.voxelSize, 3.0);
  EXPECT_NEAR(gridSum(*g.density) * std::pow(double(p.voxelSize), 3.0), mass, 1e-5 * mass);
  // The spacing estimate finds s = 4 voxels (one particle per 4³ voxels; n <= 1 at the rim, so
  // r = r_max = 4 there too): tents of half-width s form a partition of unity, so between the
  // outermost particles every voxel holds the same density, R V / (s³ Δx³) = 1 / 512, and the
  // particles' temperature (Σ k = 1), up to float rounding. No voxel is empty.
  const openvdb::FloatTree& rho = g.density->tree();
  for (int i = 1; i <= 29; ++i)
    for (int j = 1; j <= 29; ++j)
      for (int k = 1; k <= 29; ++k) {
        ASSERT_NEAR(rho.getValue(openvdb::Coord(i, j, k)), 1.f / 512.f, 1e-4f / 512.f) << i << " " << j << " " << k;
        ASSERT_NEAR(g.temperature->tree().getValue(openvdb::Coord(i, j, k)), 2.f, 1e-4f);
      }
  // The one-voxel hat on the same particles lights only the particles' own voxels, 1 in 64
  // (their neighbours get float rounding of the positions: weights ~1e-6 of the peak 1/8).
  p.spacingScale = 0.f;
  const FireGrids hat = rasterizeFire(c.view(), p);
  std::size_t lit = 0;
  for (auto it = hat.density->cbeginValueOn(); it; ++it) lit += *it > 1e-4f;
  EXPECT_EQ(lit, c.x.size());
}

TEST(FireRaster, SheetsDrawnApartByTheFlowAreJoined) {
  // Six sheets as flow-graph fire emits them, one per node step Δt_n: particles Δx/2 apart in
  // x and y over 16 x 16 voxels, the sheets 3 voxels apart in z, rising at u = 3 Δx / Δt_n.
  // Each sheet is dense (the count estimate gives r = 1), so the hat leaves the two layers of
  // voxels between sheets empty; with Δt_n the radius is |u| Δt_n / Δx = 3, and tents of
  // half-width 3 at spacings 3 (z) and 1/2 (x, y) are partitions of unity: between the
  // outermost particles (3 voxels in from the rim in x, y) every voxel holds the same density.
  FireRasterParams p;
  p.voxelSize = 0.1f;
  const float dt = 0.01f;
  Cloud c;
  std::vector<glm::vec3> u;
  for (int k = 0; k < 6; ++k)
    for (int i = 0; i < 32; ++i)
      for (int j = 0; j < 32; ++j) {
        c.x.push_back(glm::vec3(0.25f + 0.5f * i, 0.25f + 0.5f * j, 3.f * k + 0.5f) * p.voxelSize);
        c.r.push_back(1.f);
        c.t.push_back(2.f);
        u.emplace_back(0.f, 0.f, 3.f * p.voxelSize / dt);
      }
  FireParticleView view = c.view();
  view.velocities = u.data();
  const FireGrids hat = rasterizeFire(view, p);
  p.sheetInterval = dt;
  const FireGrids joined = rasterizeFire(view, p);
  const float sheet = joined.density->tree().getValue(openvdb::Coord(8, 8, 6));
  EXPECT_GT(sheet, 0.f);
  for (int x = 3; x <= 12; ++x)
    for (int z = 0; z <= 15; ++z) {
      const openvdb::Coord ijk(x, 7, z);
      ASSERT_NEAR(joined.density->tree().getValue(ijk), sheet, 1e-4f * sheet) << ijk;
      if (z % 3 != 0) ASSERT_LT(hat.density->tree().getValue(ijk), 1e-4f * sheet) << ijk;
    }
}

TEST(FireRaster, ALoneParticleSpreadsOverTheLargestKernelKeepingItsTemperature) {
  FireRasterParams p;
  p.voxelSize = 0.1f;
  // At voxel centre (1, 1, 1), alone: n(x) = 0.875³ (its coarse cell's centre is 1.5 voxels
  // off on every axis: weight (1 - 0.5 / 4)³), s = 4.6 voxels > r_max = 4.
  const glm::vec3 x = glm::vec3(1.5f) * p.voxelSize;
  const float r = 1.f, t = 3.f;
  const FireGrids g = rasterizeFire({&x, &r, &t, 1}, p);
  // Tent of half-width 4 on voxel centres: k = 1, 3/4, 1/2, 1/4 at 0..3 voxels, Σ k = 4 per
  // axis: the particle's voxel gets R V / Δx³ / 4³ = (1/8) / 64; the whole mass is kept.
  const openvdb::FloatTree& rho = g.density->tree();
  EXPECT_NEAR(rho.getValue(openvdb::Coord(1, 1, 1)), 0.125f / 64.f, 1e-7f);
  EXPECT_NEAR(gridSum(*g.density), 0.125, 1e-6);
  EXPECT_EQ(g.density->activeVoxelCount(), openvdb::Index64(7 * 7 * 7));
  // Temperature: T_p at its centre (peak weight 1), fading to ambient (0) with k.
  EXPECT_NEAR(g.temperature->tree().getValue(openvdb::Coord(1, 1, 1)), 3.f, 1e-6f);
  EXPECT_NEAR(g.temperature->tree().getValue(openvdb::Coord(4, 1, 1)), 0.75f, 1e-6f);
  EXPECT_NEAR(g.temperature->tree().getValue(openvdb::Coord(3, 3, 1)), 0.75f, 1e-6f);
}

TEST(FireRaster, DeterministicAndWrittenAsAFrameVdb) {
  // Dense (every kernel the one-voxel hat) and sparse (kernels of 2-4 voxels, overlapping
  // across leaves, which several threads sum into) clouds, with velocities.
  FireGrids g[2];
  for (int count : {2000, 30000}) {
    const Cloud c = randomCloud(count);
    std::vector<glm::vec3> u;
    for (std::size_t n = 0; n < c.x.size(); ++n) u.push_back(c.x[n] * c.t[n]);
    for (int t = 0; t < 2; ++t) {
      FireRasterParams p;
      p.voxelSize = 1.f / 48.f;
      p.threads = t + 1;
      FireParticleView view = c.view();
      view.velocities = u.data();
      g[t] = rasterizeFire(view, p);
    }
    for (auto pick : {&FireGrids::density, &FireGrids::temperature, &FireGrids::flame}) {
      const openvdb::FloatGrid& a = *(g[0].*pick);
      const openvdb::FloatGrid& b = *(g[1].*pick);
      ASSERT_EQ(a.activeVoxelCount(), b.activeVoxelCount());
      for (auto it = a.cbeginValueOn(); it; ++it) ASSERT_EQ(*it, b.tree().getValue(it.getCoord()));
    }
    ASSERT_EQ(g[0].velocity->activeVoxelCount(), g[1].velocity->activeVoxelCount());
    for (auto it = g[0].velocity->cbeginValueOn(); it; ++it)
      ASSERT_EQ(*it, g[1].velocity->tree().getValue(it.getCoord()));
  }
  const std::string path = tempPath("fire_0001.vdb");
  writeFireVdb(path, g[0], 1);
  auto names = vdbGridNames(path);
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"density", "flame", "temperature", "velocity"}));
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
