/// \file mantaflow_test.cpp
/// Streaklines driven by a Mantaflow cache ([Smoke Surfaces] §3.2): synthetic
/// fluid_data VDB files laid out as Blender 3.4 writes them (staggered velocity in cells per
/// Mantaflow time unit, uniform voxel size, no translation, voxels only where there is smoke)
/// read onto the world grid, every mismatch rejected with the file name, the volume frames
/// written back, and the frame driver: exact in a field linear in time, second order in time,
/// deterministic across thread counts.

#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <string>

#include "core/parallel.h"
#include "io/mantaflow_cache.h"
#include "tracers/mantaflow_driver.h"
#include "tests/temp_path.h"

namespace plume {
namespace {

/// A domain 1.2 x 1.25 x 1.2 over 6 x 8 x 5 cells: cells of 0.2 x 0.15625 x 0.24, not cubic,
/// as Blender stretches the box over its base resolution. The longest side is y.
MantaflowGrid testGrid() {
  return MantaflowGrid{glm::ivec3(6, 8, 5), glm::vec3(-0.5f, 1.f, 0.25f),
                       glm::vec3(0.2f, 0.15625f, 0.24f), kMantaflowTimeUnitsPerSecond};
}

/// How a synthetic file departs from what Blender writes.
struct Tweak {
  bool centred = false;           ///< velocity class unknown (cell-centred) instead of staggered
  bool noVelocity = false;        ///< velocity grid missing
  bool densityAsVector = false;   ///< `density` written as a vec3 grid
  double voxelScale = 1.0;        ///< voxel size off by this factor
  double translate = 0.0;         ///< transform translated by this much on x
  glm::ivec3 metaResolution{-1};  ///< file_base_resolution metadata (-1: the grid's)
  bool strayVoxel = false;        ///< a density voxel outside the grid
  bool nan = false;               ///< a NaN velocity
};

/// Writes a Mantaflow-like frame: voxels where density(ijk) > 0, each holding density(ijk) and
/// velocity(ijk) (staggered: the lower faces' values, cells per time unit).
void writeFrame(const std::string& path, const MantaflowGrid& g,
                const std::function<float(glm::ivec3)>& density,
                const std::function<glm::vec3(glm::ivec3)>& velocity, const Tweak& tweak = {}) {
  openvdb::initialize();
  auto xform =
      openvdb::math::Transform::createLinearTransform(double(g.vdbVoxelSize()) * tweak.voxelScale);
  if (tweak.translate != 0.0) xform->postTranslate(openvdb::Vec3d(tweak.translate, 0.0, 0.0));
  auto d = openvdb::FloatGrid::create(0.f);
  auto v = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.f));
  auto dv = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.f));
  const glm::ivec3 n = g.resolution;
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const float rho = density({i, j, k});
        if (!(rho > 0.f)) continue;
        const glm::vec3 u = velocity({i, j, k});
        d->tree().setValue(openvdb::Coord(i, j, k), rho);
        dv->tree().setValue(openvdb::Coord(i, j, k), openvdb::Vec3s(rho));
        v->tree().setValue(openvdb::Coord(i, j, k), openvdb::Vec3s(u.x, u.y, u.z));
      }
  if (tweak.strayVoxel) d->tree().setValue(openvdb::Coord(n.x, 0, 0), 1.f);
  if (tweak.nan) v->tree().setValue(openvdb::Coord(0, 0, 0), openvdb::Vec3s(std::nanf("")));
  const glm::ivec3 meta = tweak.metaResolution.x < 0 ? n : tweak.metaResolution;
  openvdb::GridPtrVec grids;
  if (tweak.densityAsVector)
    grids.push_back(dv);
  else
    grids.push_back(d);
  if (!tweak.noVelocity) grids.push_back(v);
  grids[0]->setName("density");
  v->setName("velocity");
  v->setGridClass(tweak.centred ? openvdb::GRID_UNKNOWN : openvdb::GRID_STAGGERED);
  for (auto& grid : grids) {
    grid->setTransform(xform);
    grid->insertMeta("file_base_resolution",
                     openvdb::Vec3IMetadata(openvdb::Vec3i(meta.x, meta.y, meta.z)));
  }
  openvdb::io::File file(path);
  file.write(grids);
  file.close();
}

std::string tempPath(const std::string& name) {
  return plume::test::tempPath("mantaflow_" + name);
}

/// Smoke in the box [1,3] x [2,5] x [1,2] of cells.
float boxDensity(glm::ivec3 c) {
  return c.x >= 1 && c.x <= 3 && c.y >= 2 && c.y <= 5 && c.z >= 1 && c.z <= 2
             ? 0.5f + 0.1f * float(c.x)
             : 0.f;
}

glm::vec3 codedVelocity(glm::ivec3 c) {
  return {float(c.x) + 10.f * float(c.y) + 100.f * float(c.z), -1.f - float(c.y), 2.f + float(c.z)};
}

TEST(MantaflowCache, ReadsStaggeredVelocityFaceByFaceInMetresPerSecond) {
  const MantaflowGrid g = testGrid();
  const std::string path = tempPath("staggered.vdb");
  writeFrame(path, g, boxDensity, codedVelocity);
  const MantaflowFrame f = readMantaflowFrame(path, g);
  ASSERT_EQ(f.density.size(), g.resolution);
  EXPECT_FLOAT_EQ(f.density(2, 3, 1), 0.7f);
  EXPECT_EQ(f.density(0, 0, 0), 0.f);
  // cells per time unit * cell size * 2.5 time units per second, per axis.
  const glm::vec3 scale = g.cellSize * 2.5f;
  const ScalarGrid &u = f.velocity.u(), &v = f.velocity.v(), &w = f.velocity.w();
  // A stored voxel's lower faces are its values.
  EXPECT_FLOAT_EQ(u(2, 3, 1), codedVelocity({2, 3, 1}).x * scale.x);
  EXPECT_FLOAT_EQ(v(2, 3, 1), codedVelocity({2, 3, 1}).y * scale.y);
  EXPECT_FLOAT_EQ(w(2, 3, 1), codedVelocity({2, 3, 1}).z * scale.z);
  // The upper face of the smoke's last cell is not in the file: it takes that cell's lower face.
  EXPECT_FLOAT_EQ(u(4, 3, 1), codedVelocity({3, 3, 1}).x * scale.x);
  EXPECT_FLOAT_EQ(v(2, 6, 1), codedVelocity({2, 5, 1}).y * scale.y);
  EXPECT_FLOAT_EQ(w(2, 3, 3), codedVelocity({2, 3, 2}).z * scale.z);
  // Faces away from the smoke are zero, also beyond one face.
  EXPECT_EQ(u(5, 3, 1), 0.f);
  EXPECT_EQ(w(2, 3, 4), 0.f);
  EXPECT_EQ(v(0, 0, 0), 0.f);
  std::remove(path.c_str());
}

TEST(MantaflowCache, TopFacesOfTheGridAndCellCentredVelocity) {
  const MantaflowGrid g = testGrid();
  auto everywhere = [](glm::ivec3) { return 1.f; };
  const std::string path = tempPath("full.vdb");
  writeFrame(path, g, everywhere, codedVelocity);
  MantaflowFrame f = readMantaflowFrame(path, g);
  const float sx = g.cellSize.x * 2.5f;
  // Face nx is outside Mantaflow's grid: the last cell's lower face.
  EXPECT_FLOAT_EQ(f.velocity.u()(6, 4, 2), codedVelocity({5, 4, 2}).x * sx);

  Tweak centred;
  centred.centred = true;
  writeFrame(path, g, everywhere, codedVelocity, centred);
  f = readMantaflowFrame(path, g);
  // Inner faces: the mean of the two cells; outer faces: the one cell.
  EXPECT_FLOAT_EQ(f.velocity.u()(3, 4, 2),
                  0.5f * (codedVelocity({2, 4, 2}).x + codedVelocity({3, 4, 2}).x) * sx);
  EXPECT_FLOAT_EQ(f.velocity.u()(0, 4, 2), codedVelocity({0, 4, 2}).x * sx);
  EXPECT_FLOAT_EQ(f.velocity.u()(6, 4, 2), codedVelocity({5, 4, 2}).x * sx);
  std::remove(path.c_str());
}

/// Every mismatch is a std::runtime_error that names the file.
TEST(MantaflowCache, RejectsWhatDoesNotMatchTheGridNamingTheFile) {
  const MantaflowGrid g = testGrid();
  const std::string path = tempPath("bad.vdb");
  auto expectFailure = [&](const Tweak& t, const char* what) {
    writeFrame(path, g, boxDensity, codedVelocity, t);
    try {
      readMantaflowFrame(path, g);
      ADD_FAILURE() << "no error for " << what;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  };
  Tweak t;
  t.noVelocity = true;
  expectFailure(t, "a missing velocity grid");
  t = {};
  t.densityAsVector = true;
  expectFailure(t, "a density of another type");
  t = {};
  t.voxelScale = 1.01;
  expectFailure(t, "another voxel size");
  t = {};
  t.translate = 0.3;
  expectFailure(t, "a translated transform");
  t = {};
  t.metaResolution = glm::ivec3(6, 8, 6);
  expectFailure(t, "another base resolution");
  t = {};
  t.strayVoxel = true;
  expectFailure(t, "a voxel outside the grid");
  t = {};
  t.nan = true;
  expectFailure(t, "a NaN");
  std::remove(path.c_str());
  EXPECT_THROW(readMantaflowFrame(tempPath("missing.vdb"), g), std::runtime_error);
  MantaflowGrid bad = g;
  bad.cellSize.x = 0.f;
  EXPECT_THROW(readMantaflowFrame(path, bad), std::runtime_error);
}

TEST(MantaflowCache, VolumeFrameIsPlacedInWorldSpace) {
  const MantaflowGrid g = testGrid();
  const std::string in = tempPath("in.vdb"), out = tempPath("volume.vdb");
  writeFrame(in, g, boxDensity, codedVelocity);
  const MantaflowFrame f = readMantaflowFrame(in, g);
  writeMantaflowVolume(out, f, g, 7);
  openvdb::io::File file(out);
  file.open();
  auto density = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("density"));
  auto velocity = openvdb::gridPtrCast<openvdb::Vec3SGrid>(file.readGrid("velocity"));
  file.close();
  ASSERT_TRUE(density && velocity);
  EXPECT_EQ(density->activeVoxelCount(), openvdb::Index64(3 * 4 * 2));
  EXPECT_FLOAT_EQ(density->tree().getValue(openvdb::Coord(2, 3, 1)), 0.7f);
  const openvdb::Vec3d c = density->indexToWorld(openvdb::Coord(2, 3, 1));
  const glm::vec3 expected = g.indexToWorld(glm::vec3(2.5f, 3.5f, 1.5f));
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(c[a], expected[a], 1e-6);
  // Cell-centred velocity where there is smoke, nothing elsewhere.
  const glm::vec3 centre = f.velocity.cellCenter(2, 3, 1);
  EXPECT_FLOAT_EQ(velocity->tree().getValue(openvdb::Coord(2, 3, 1))[2], centre.z);
  EXPECT_FALSE(velocity->tree().isValueOn(openvdb::Coord(0, 0, 0)));
  std::remove(in.c_str());
  std::remove(out.c_str());
}

/// Frames on testGrid() with face velocity `u` (m/s) everywhere and no smoke.
MantaflowFrame uniformFrame(glm::vec3 u) {
  MantaflowFrame f = MantaflowFrame::empty(testGrid().resolution);
  for (int a = 0; a < 3; ++a) f.velocity.component(a).fill(u[a]);
  return f;
}

MantaflowTraceParams traceParams(float cfl = 1.f) {
  MantaflowTraceParams p;
  p.streak.interpolation = Interpolation::Linear;
  p.cfl = cfl;
  return p;
}

const std::array<Boundary, 6> kOpen{Boundary::Open, Boundary::Open, Boundary::Open,
                                    Boundary::Open, Boundary::Open, Boundary::Open};

TEST(MantaflowTracer, VelocityLinearInTimeIsIntegratedExactlyInWorldSpace) {
  const MantaflowGrid g = testGrid();
  MantaflowTracer tracer(traceParams(), g, kOpen);
  const glm::vec3 start(0.1f, 1.6f, 0.6f);
  tracer.addPointSources({start}, {0});
  const glm::vec3 u(0.3f, -0.2f, 0.5f);  // m/s
  const float frameDt = 1.f / 24.f;
  const MantaflowFrame rest = MantaflowFrame::empty(g.resolution), moving = uniformFrame(u);
  // From rest to u over one frame: the particle moves u T / 2 (the midpoint rule is exact for
  // a velocity linear in time); then u T per frame.
  const int n1 = tracer.advanceFrame(rest, moving, frameDt);
  EXPECT_EQ(n1, tracer.substeps(rest, moving, frameDt));
  const int n2 = tracer.advanceFrame(moving, moving, frameDt);
  StreakFrame s = tracer.snapshot();
  ASSERT_EQ(s.counts.size(), 1u);
  ASSERT_EQ(s.counts[0], 1 + n1 + n2);
  const glm::vec3 oldest = s.positions[0];
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(oldest[a], start[a] + 1.5f * u[a] * frameDt, 1e-5f);
  // Substeps: the fastest axis in cells per frame (0.5 m/s over 0.24 m cells = 2.08 cells/s).
  const float cellsPerFrame = std::max({0.3f / 0.2f, 0.2f / 0.15625f, 0.5f / 0.24f}) * frameDt;
  EXPECT_EQ(n2, std::max(1, int(std::ceil(cellsPerFrame))));
  MantaflowTracer fine(traceParams(0.05f), g, kOpen);
  EXPECT_EQ(fine.substeps(moving, moving, frameDt), int(std::ceil(cellsPerFrame / 0.05f)));
}

/// Solid rotation about the domain's centre axis (z), steady: an exact circle to compare with.
MantaflowFrame rotation(const MantaflowGrid& g, float omega) {
  MantaflowFrame f = MantaflowFrame::empty(g.resolution);
  const glm::vec3 centre = g.indexToWorld(glm::vec3(g.resolution) * 0.5f);
  for (int a = 0; a < 2; ++a) {
    ScalarGrid& c = f.velocity.component(a);
    const glm::ivec3 s = c.size();
    for (int k = 0; k < s.z; ++k)
      for (int j = 0; j < s.y; ++j)
        for (int i = 0; i < s.x; ++i) {
          glm::vec3 p = glm::vec3(i, j, k) + 0.5f;
          p[a] -= 0.5f;
          const glm::vec3 x = g.indexToWorld(p) - centre;
          c(i, j, k) = a == 0 ? -omega * x.y : omega * x.x;
        }
  }
  return f;
}

float rotationError(float cfl) {
  const MantaflowGrid g = testGrid();
  MantaflowTracer tracer(traceParams(cfl), g, kOpen);
  const glm::vec3 centre = g.indexToWorld(glm::vec3(g.resolution) * 0.5f);
  const glm::vec3 start = centre + glm::vec3(0.25f, 0.f, 0.f);
  tracer.addPointSources({start}, {0});
  const float omega = 6.f, frameDt = 1.f / 24.f;
  const MantaflowFrame f = rotation(g, omega);
  for (int n = 0; n < 6; ++n) tracer.advanceFrame(f, f, frameDt);
  const float angle = omega * 6.f * frameDt;
  const glm::vec3 exact = centre + 0.25f * glm::vec3(std::cos(angle), std::sin(angle), 0.f);
  return glm::length(tracer.snapshot().positions[0] - exact);
}

TEST(MantaflowTracer, SecondOrderInTime) {
  // The field is linear in space, so trilinear sampling is exact and only time steps err.
  const float coarse = rotationError(1.f), fine = rotationError(0.5f);
  EXPECT_GT(coarse, 0.f);
  EXPECT_GT(coarse / fine, 3.f);  // 4 for second order; 2 would be first order
  EXPECT_LT(coarse / fine, 5.f);
}

StreakFrame swirlTrace(int threads) {
  ThreadLimit limit(threads);
  const MantaflowGrid g = testGrid();
  MantaflowTraceParams p;
  p.streak.emissionPeriod = 2;
  MantaflowTracer tracer(p, g, kOpen);
  std::vector<glm::vec3> points;
  for (int n = 0; n < 300; ++n)
    points.push_back(g.indexToWorld(
        glm::vec3(1.f + 0.013f * float(n), 2.f + 0.011f * float(n), 1.f + 0.007f * float(n))));
  tracer.addPointSources(points, std::vector<int>(points.size(), 0));
  MantaflowFrame a = rotation(g, 5.f), b = rotation(g, -3.f);
  b.density.fill(0.25f);
  tracer.advanceFrame(MantaflowFrame::empty(g.resolution), a, 1.f / 24.f);
  tracer.advanceFrame(a, b, 1.f / 24.f);
  return tracer.snapshot();
}

TEST(MantaflowTracer, DeterministicAcrossThreadCounts) {
  const StreakFrame one = swirlTrace(1), two = swirlTrace(2);
  ASSERT_EQ(one.positions.size(), two.positions.size());
  EXPECT_EQ(0, std::memcmp(one.positions.data(), two.positions.data(),
                           one.positions.size() * sizeof(glm::vec3)));
  EXPECT_EQ(one.density, two.density);
  EXPECT_FLOAT_EQ(one.density[0], 0.25f);  // sampled from the end-of-frame density
}

TEST(MantaflowTracer, RejectsBadInputAndCancels) {
  const MantaflowGrid g = testGrid();
  EXPECT_THROW(MantaflowTracer(traceParams(0.f), g, kOpen), std::invalid_argument);
  MantaflowTracer tracer(traceParams(), g, kOpen);
  const glm::vec3 hi = g.indexToWorld(glm::vec3(g.resolution));
  EXPECT_THROW(tracer.addPointSources({hi + glm::vec3(0.01f)}, {0}), std::invalid_argument);
  EXPECT_EQ(tracer.addPointSources({g.origin, hi}, {0, 0}), 0);  // the box's corners are inside
  const MantaflowFrame f = uniformFrame(glm::vec3(0.1f));
  EXPECT_THROW(tracer.advanceFrame(f, f, 0.f), std::invalid_argument);
  EXPECT_THROW(tracer.advanceFrame(f, MantaflowFrame::empty({2, 2, 2}), 0.1f),
               std::invalid_argument);
  // A broken cache asking for millions of substeps is refused, not run.
  EXPECT_THROW(tracer.advanceFrame(f, uniformFrame(glm::vec3(1e7f)), 0.1f), std::runtime_error);
  tracer.cancel();
  EXPECT_EQ(tracer.advanceFrame(f, f, 0.1f), 0);
}

}  // namespace
}  // namespace plume
