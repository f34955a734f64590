#pragma once
/// \file vdb_seeds.h
/// Small VDB files made by OpenVDB's own writer, the starting points of the hostile-file tests
/// (tests/vdb_hostile_test.cpp) and the seed corpus of the VDB fuzz targets: a Plume volume
/// frame (float and vec3s grids, Blosc, written by writeGridsAtomic) and a Mantaflow frame as
/// Blender 3.4 lays it out (staggered velocity, half floats optional, uniform voxel size).

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <string>
#include <vector>

#include "io/mantaflow_cache.h"
#include "io/vdb_grids.h"

namespace plume::seeds {

/// The Mantaflow domain of the seeds: 6 x 8 x 5 cells of 0.2 x 0.15625 x 0.24.
inline MantaflowGrid mantaflowGrid() {
  return MantaflowGrid{glm::ivec3(6, 8, 5), glm::vec3(-0.5f, 1.f, 0.25f),
                       glm::vec3(0.2f, 0.15625f, 0.24f), kMantaflowTimeUnitsPerSecond};
}

/// Smoke in cells [1,3] x [2,5] x [1,2] (24 voxels: small leaves that Blosc stores
/// uncompressed, next to the compressed ones of the other grids).
inline bool inSmoke(int i, int j, int k) {
  return i >= 1 && i <= 3 && j >= 2 && j <= 5 && k >= 1 && k <= 2;
}

/// A Mantaflow fluid_data frame on mantaflowGrid(): density, a staggered velocity, a
/// temperature and file_base_resolution metadata; `half` stores floats as 16-bit halves (Blender's
/// default cache depth).
inline void writeMantaflowSeed(const std::string& path, bool half) {
  initializeOpenVdb();
  const MantaflowGrid g = mantaflowGrid();
  auto xform = openvdb::math::Transform::createLinearTransform(double(g.vdbVoxelSize()));
  auto d = openvdb::FloatGrid::create(0.f);
  auto t = openvdb::FloatGrid::create(0.f);
  auto v = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.f));
  for (int k = 0; k < g.resolution.z; ++k)
    for (int j = 0; j < g.resolution.y; ++j)
      for (int i = 0; i < g.resolution.x; ++i) {
        if (!inSmoke(i, j, k)) continue;
        const openvdb::Coord c(i, j, k);
        d->tree().setValue(c, 0.5f + 0.1f * float(i));
        t->tree().setValue(c, 1.f + 0.01f * float(j));
        v->tree().setValue(c, openvdb::Vec3s(float(i) + 10.f * float(j), -1.f - float(j), 2.f));
      }
  d->setName("density");
  t->setName("temperature");
  v->setName("velocity");
  v->setGridClass(openvdb::GRID_STAGGERED);
  openvdb::GridPtrVec grids{d, v, t};
  for (auto& grid : grids) {
    grid->setTransform(xform);
    grid->setSaveFloatAsHalf(half);
    grid->insertMeta("file_base_resolution",
                     openvdb::Vec3IMetadata(openvdb::Vec3i(g.resolution.x, g.resolution.y,
                                                           g.resolution.z)));
  }
  openvdb::io::File file(path);
  file.write(grids);
  file.close();
}

/// A Plume volume frame of n = 12 x 10 x 9 cells: density, temperature and velocity from dense
/// arrays, through the writer of the bake (Blosc, active-mask compression, atomic rename).
inline void writePlumeFrameSeed(const std::string& path) {
  const glm::ivec3 n(12, 10, 9);
  std::vector<float> density(std::size_t(n.x * n.y * n.z), 0.f), temperature(density.size());
  std::vector<openvdb::Vec3s> velocity(density.size(), openvdb::Vec3s(0.f));
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const std::size_t m = std::size_t(i + n.x * (j + n.y * k));
        if ((i - 6) * (i - 6) + (j - 5) * (j - 5) + (k - 4) * (k - 4) < 12)
          density[m] = 1.f / float(1 + i + j);
        temperature[m] = density[m] * 3.f;
        if (density[m] > 0.f) velocity[m] = openvdb::Vec3s(0.1f * float(i), 1.f, -0.5f);
      }
  const auto xform = cellCenteredTransform(0.1f, glm::vec3(-0.6f, 0.f, -0.45f));
  openvdb::GridPtrVec grids{denseFloatGrid("density", density.data(), n, xform),
                            denseFloatGrid("temperature", temperature.data(), n, xform),
                            denseVectorGrid("velocity", velocity.data(), n, xform)};
  openvdb::MetaMap meta;
  meta.insertMeta("creator", openvdb::StringMetadata("plume"));
  writeGridsAtomic(path, grids, meta);
}

}  // namespace plume::seeds
