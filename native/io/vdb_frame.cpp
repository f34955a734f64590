/// \file vdb_frame.cpp
/// Per-frame VDB files: dense solver grids to sparse OpenVDB grids (zero voxels skipped) and back.

#include "io/vdb_frame.h"

#include "core/huge_pages.h"
#include "core/parallel.h"
#include "io/utf8_text.h"
#include "io/vdb_grids.h"
#include "io/vdb_guard.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace plume {
namespace {

/// An error already naming the file (not wrapped again).
struct VdbFrameError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw VdbFrameError(cleanUtf8("VDB file '" + path + "': " + what));
}

}  // namespace

void writeVdbFrame(const std::string& path, const SmokeSolver& solver, bool velocityEverywhere) {
  initializeOpenVdb();
  const SmokeParams& p = solver.params();
  const glm::ivec3 n = p.resolution;
  const auto xform = cellCenteredTransform(p.cellSize, p.origin);
  const int slabs = n.z;
  const std::size_t slab = std::size_t(n.x) * std::size_t(n.y);

  openvdb::GridPtrVec grids;
  // The dense staging arrays (33 MB at 128³) are kept from frame to frame: allocated anew, their
  // pages were faulted in again on every frame, which cost more than writing the file (Blender's
  // allocator returns large blocks to the system).
  // Per calling thread (two bakes may write at once); the tasks below use the caller's arrays
  // through these references (a thread_local named in a task would be the worker's own).
  thread_local std::vector<float> densityStage;
  thread_local std::vector<openvdb::Vec3s> velocityStage;
  std::vector<float>& density = densityStage;
  std::vector<openvdb::Vec3s>& velocity = velocityStage;
  // Blender's Principled Volume reads `density`: what it shows is smoke plus soot.
  reserveHugePages(density, solver.density().count());
  density.resize(solver.density().count());
  {
    const float* d = solver.density().data();
    const float* s = solver.soot().data();
    parallelFor(0, slabs, [&](int k) {
      for (std::size_t m = std::size_t(k) * slab, e = m + slab; m < e; ++m) density[m] = d[m] + s[m];
    });
    grids.push_back(denseFloatGrid("density", density.data(), n, xform));
  }
  grids.push_back(denseFloatGrid("temperature", solver.temperature().data(), n, xform));
  if (p.combustion) grids.push_back(denseFloatGrid("flame", solver.flame().data(), n, xform));
  {
    // Cell-centred velocity (the mean of each cell's two faces per axis), stored only where
    // there is smoke or flame: the projection leaves tiny velocities in the whole domain, which
    // would make every frame a dense grid (270 MB for ten frames at 128³) for motion blur only.
    // velocityEverywhere keeps them all: the domain is then a wind field (§6.1 of the flames).
    reserveHugePages(velocity, solver.density().count());
    velocity.resize(solver.density().count());
    const MacGrid3& mac = solver.velocity();
    const float* flame = solver.flame().data();
    const bool burning = p.combustion;
    parallelFor(0, slabs, [&](int k) {
      for (int j = 0; j < n.y; ++j)
        for (int i = 0; i < n.x; ++i) {
          const std::size_t m = std::size_t(i) + std::size_t(n.x) * (std::size_t(j) + std::size_t(n.y) * k);
          const bool visible =
              velocityEverywhere || density[m] != 0.f || (burning && flame[m] != 0.f);
          const glm::vec3 c = visible ? mac.cellCenter(i, j, k) : glm::vec3(0.f);
          velocity[m] = openvdb::Vec3s(c.x, c.y, c.z);
        }
    });
    grids.push_back(denseVectorGrid("velocity", velocity.data(), n, xform));
  }

  openvdb::MetaMap meta;
  meta.insertMeta("creator", openvdb::StringMetadata("plume"));
  meta.insertMeta("frame", openvdb::Int32Metadata(solver.frame()));
  writeGridsAtomic(path, grids, meta);
}

std::vector<std::string> vdbGridNames(const std::string& path) {
  try {
    return CheckedVdbFile(path).gridNames();
  } catch (const std::exception& e) {
    fail(path, std::string("cannot be read: ") + e.what());
  }
}

namespace {

/// Copies the active bounding box of a grid into a dense x-fastest array.
template <typename GridT>
void readDense(const GridT& grid, DenseGrid& out, const std::string& path) {
  const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
  out.min = glm::ivec3(box.min().x(), box.min().y(), box.min().z());
  if (box.empty()) {
    out.size = glm::ivec3(0);
    return;
  }
  // Where the box lies, before any size is computed from it: copyToDense works in int
  // coordinates, and a box near 2^31 overflows them (the tree check keeps nodes within 2^24).
  constexpr int kLimit = 1 << 24;
  for (int a = 0; a < 3; ++a)
    if (box.min()[a] < -kLimit || box.max()[a] >= kLimit)
      fail(path, "grid '" + out.name + "' has voxels outside [-2^24, 2^24) on axis " +
                     std::to_string(a));
  const openvdb::Coord dim = box.dim();
  const double count = double(dim.x()) * dim.y() * dim.z() * out.components;
  // A file is never trusted: refuse boxes no solver could have written.
  if (count > 1024.0 * 1024.0 * 1024.0)
    fail(path, "grid '" + out.name + "' spans too many voxels to read densely");
  out.size = glm::ivec3(dim.x(), dim.y(), dim.z());
  using ValueT = typename GridT::ValueType;
  std::vector<ValueT> values(std::size_t(dim.x()) * dim.y() * dim.z(), grid.background());
  openvdb::tools::Dense<ValueT, openvdb::tools::LayoutXYZ> dense(box, values.data());
  openvdb::tools::copyToDense(grid, dense);
  if constexpr (std::is_same_v<ValueT, float>) {
    out.values = std::move(values);
  } else {
    out.values.resize(values.size() * 3);
    for (std::size_t m = 0; m < values.size(); ++m)
      for (int c = 0; c < 3; ++c) out.values[3 * m + std::size_t(c)] = values[m][c];
  }
}

/// The dense box of a grid read from `path`, with its placement (finite, positive voxel size).
DenseGrid denseOf(const openvdb::GridBase& base, const std::string& name, const std::string& path) {
  DenseGrid out;
  out.name = name;
  const openvdb::Vec3d voxel = base.voxelSize();
  const openvdb::Vec3d w0 = base.indexToWorld(openvdb::Vec3d(0.0));
  for (int a = 0; a < 3; ++a)
    if (!(voxel[a] > 0.0) || !std::isfinite(float(voxel[a])) || !std::isfinite(float(w0[a])))
      fail(path, "grid '" + name + "' has a voxel size or origin that is not a finite "
                 "positive number");
  out.voxelSize = float(voxel[0]);
  out.voxelSizes = glm::vec3(float(voxel[0]), float(voxel[1]), float(voxel[2]));
  out.axisAligned = base.transform().isLinear() &&
                    base.transform().baseMap()->getAffineMap()->isScaleTranslate();
  out.worldOfVoxelZero = glm::vec3(float(w0[0]), float(w0[1]), float(w0[2]));
  if (auto g = dynamic_cast<const openvdb::FloatGrid*>(&base)) {
    out.components = 1;
    readDense(*g, out, path);
  } else if (auto v = dynamic_cast<const openvdb::Vec3SGrid*>(&base)) {
    out.components = 3;
    readDense(*v, out, path);
  } else {
    fail(path, "grid '" + name + "' is of type " + base.type() + "; expected float or vec3s");
  }
  return out;
}

}  // namespace

DenseGrid readVdbGrid(const std::string& path, const std::string& name) {
  initializeOpenVdb();
  try {
    const openvdb::GridBase::Ptr base = CheckedVdbFile(path).readGrid(name);
    if (!base) fail(path, "has no grid named '" + name + "'");
    return denseOf(*base, name, path);
  } catch (const VdbFrameError&) {
    throw;
  } catch (const std::bad_alloc&) {
    fail(path, "grid '" + name + "' does not fit in memory");
  } catch (const std::exception& e) {
    fail(path, std::string("cannot be read: ") + e.what());
  }
}

}  // namespace plume
