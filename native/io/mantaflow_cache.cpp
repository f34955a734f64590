/// \file mantaflow_cache.cpp
/// Mantaflow VDB frames to dense Plume fields (checked against the expected grid) and back to a
/// Plume volume frame.

#include "io/mantaflow_cache.h"


#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/parallel.h"
#include "io/mac_faces.h"
#include "io/utf8_text.h"
#include "io/vdb_grids.h"
#include "io/vdb_guard.h"

namespace plume {
namespace {

std::string text(glm::ivec3 v) {
  std::ostringstream s;
  s << "(" << v.x << ", " << v.y << ", " << v.z << ")";
  return s.str();
}

/// An error already naming the file (not wrapped again).
struct MantaflowFileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw MantaflowFileError(cleanUtf8("Mantaflow cache file '" + path + "': " + what));
}

/// Relative tolerance of the voxel size check: Blender stores it as a float computed from
/// the domain size, and the domain size we compute goes through other float operations.
constexpr double kVoxelSizeTolerance = 1e-4;

/// Mantaflow's transform: uniform scale `voxel`, no rotation, no translation.
void checkTransform(const openvdb::GridBase& grid, const MantaflowGrid& g,
                    const std::string& path) {
  const openvdb::math::Transform& xf = grid.transform();
  const openvdb::Vec3d size = grid.voxelSize();
  const double expected = double(g.vdbVoxelSize());
  bool ok = xf.isLinear();
  for (int a = 0; a < 3 && ok; ++a)
    ok = std::abs(size[a] - expected) <= kVoxelSizeTolerance * expected;
  if (!ok) {
    std::ostringstream s;
    s << "grid '" << grid.getName() << "' has voxel size (" << size[0] << ", " << size[1] << ", "
      << size[2] << "); the Mantaflow domain's grid " << text(g.resolution) << " expects "
      << expected << " (longest side / resolution): the file belongs to another domain or "
      << "resolution; bake the Mantaflow domain again";
    fail(path, s.str());
  }
  // Index (0,0,0) at the world origin and each index axis along its world axis.
  bool plain = xf.indexToWorld(openvdb::Vec3d(0.0)).length() <= kVoxelSizeTolerance * expected;
  for (int a = 0; a < 3 && plain; ++a) {
    openvdb::Vec3d e(0.0);
    e[a] = 1.0;
    openvdb::Vec3d d = xf.indexToWorld(e) - xf.indexToWorld(openvdb::Vec3d(0.0));
    d[a] = 0.0;
    plain = d.length() <= kVoxelSizeTolerance * expected;
  }
  if (!plain)
    fail(path, "grid '" + grid.getName() +
                   "' has a translated or rotated transform; Blender's Mantaflow writes a plain "
                   "scale (is this a Mantaflow cache?)");
}

/// The base resolution Mantaflow stores as metadata, when present, must be the grid's.
void checkResolution(const openvdb::GridBase& grid, const MantaflowGrid& g,
                     const std::string& path) {
  if (auto meta = grid.getMetadata<openvdb::Vec3IMetadata>("file_base_resolution")) {
    const openvdb::Vec3i r = meta->value();
    if (glm::ivec3(r[0], r[1], r[2]) != g.resolution)
      fail(path, "grid '" + grid.getName() + "' has base resolution " +
                     text(glm::ivec3(r[0], r[1], r[2])) + "; the Mantaflow domain's grid is " +
                     text(g.resolution) + ": bake the Mantaflow domain again");
  }
  const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
  if (box.empty()) return;
  const openvdb::CoordBBox inside(
      openvdb::Coord(0),
      openvdb::Coord(g.resolution.x - 1, g.resolution.y - 1, g.resolution.z - 1));
  if (!inside.isInside(box))
    fail(path, "grid '" + grid.getName() + "' has voxels from " +
                   text(glm::ivec3(box.min().x(), box.min().y(), box.min().z())) + " to " +
                   text(glm::ivec3(box.max().x(), box.max().y(), box.max().z())) +
                   ", outside the Mantaflow grid " + text(g.resolution) +
                   " (adaptive domain or another resolution?)");
}

template <typename GridT>
typename GridT::Ptr readGrid(const CheckedVdbFile& file, const std::string& name,
                             const MantaflowGrid& g, const std::string& path) {
  openvdb::GridBase::Ptr base = file.readGrid(name);
  if (!base) fail(path, "has no grid named '" + name + "'");
  auto grid = openvdb::gridPtrCast<GridT>(base);
  if (!grid)
    fail(path,
         "grid '" + name + "' is of type " + base->type() + "; expected " + GridT::gridType());
  checkTransform(*grid, g, path);
  checkResolution(*grid, g, path);
  return grid;
}

/// Per k-slab, the value and active state of every voxel of the grid box (x fastest).
template <typename GridT, typename Store>
void forEachVoxel(const GridT& grid, glm::ivec3 n, const Store& store) {
  parallelFor(0, n.z, [&](int k) {
    auto acc = grid.getConstAccessor();  // one accessor per slab: accessors are not shared
    typename GridT::ValueType value;
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const bool on = acc.probeValue(openvdb::Coord(i, j, k), value);
        store(i, j, k, value, on);
      }
  });
}

std::size_t cellIndex(glm::ivec3 p, glm::ivec3 n) {
  return std::size_t(p.x) +
         std::size_t(n.x) * (std::size_t(p.y) + std::size_t(n.y) * std::size_t(p.z));
}

/// Face velocities from a staggered grid: face (i,j,k) of component a is voxel (i,j,k)'s
/// component a. A face missing from the file (voxel clipped or beyond the grid) whose lower cell
/// is stored takes that cell's lower face: constant extrapolation over one face.
void facesFromStaggered(const std::vector<openvdb::Vec3s>& v, const std::vector<std::uint8_t>& on,
                        glm::ivec3 n, MacGrid3& mac) {
  fillFaces(mac, [&](glm::ivec3 f, glm::ivec3 below, int a) {
    if (f[a] < n[a] && on[cellIndex(f, n)]) return v[cellIndex(f, n)][a];
    if (below[a] >= 0 && on[cellIndex(below, n)]) return v[cellIndex(below, n)][a];
    return 0.f;
  });
}

/// Face velocities from a cell-centred grid (another writer than Mantaflow): the mean of the
/// two cells beside the face, or the one of them the file holds.
void facesFromCentred(const std::vector<openvdb::Vec3s>& v, const std::vector<std::uint8_t>& on,
                      glm::ivec3 n, MacGrid3& mac) {
  facesFromCentres(
      mac, n, [&](glm::ivec3 p) { return on[cellIndex(p, n)] != 0; },
      [&](glm::ivec3 p, int a) { return v[cellIndex(p, n)][a]; });
}

}  // namespace

float MantaflowGrid::vdbVoxelSize() const {
  const glm::vec3 size = glm::vec3(resolution) * cellSize;
  return std::max({size.x, size.y, size.z}) /
         float(std::max({resolution.x, resolution.y, resolution.z}));
}

void MantaflowGrid::validate() const {
  for (int a = 0; a < 3; ++a) {
    if (resolution[a] < 1 || resolution[a] > kMaxMantaflowResolution)
      throw std::invalid_argument("Mantaflow resolution must be in [1, " +
                                  std::to_string(kMaxMantaflowResolution) + "] per axis (got " +
                                  text(resolution) + ")");
    if (!(cellSize[a] > 0.f) || !std::isfinite(cellSize[a]))
      throw std::invalid_argument("Mantaflow cell_size must be finite and > 0 per axis");
    if (!std::isfinite(origin[a])) throw std::invalid_argument("Mantaflow origin must be finite");
  }
  if (!(timeUnitsPerSecond > 0.f) || !std::isfinite(timeUnitsPerSecond))
    throw std::invalid_argument("Mantaflow time_units_per_second must be finite and > 0");
}

MantaflowFrame MantaflowFrame::empty(glm::ivec3 resolution) {
  MantaflowFrame f;
  f.density.resize(resolution, 0.f);
  f.velocity.resize(resolution);
  return f;
}

float MantaflowFrame::maxCellsPerSecond(const MantaflowGrid& grid) const {
  double m = 0.0;
  for (int a = 0; a < 3; ++a) {
    const ScalarGrid& c = velocity.component(a);
    const glm::ivec3 s = c.size();
    const double inv = 1.0 / double(grid.cellSize[a]);
    m = std::max(m, parallelMax(0, s.z, [&](int k) {
                   float slab = 0.f;
                   const std::size_t first = c.index(0, 0, k),
                                     count = std::size_t(s.x) * std::size_t(s.y);
                   for (std::size_t q = first; q < first + count; ++q)
                     slab = std::max(slab, std::abs(c[q]));
                   return double(slab) * inv;
                 }));
  }
  return float(m);
}

namespace {

/// readMantaflowFrame() without the translation of foreign exceptions.
MantaflowFrame readFrame(const std::string& path, const MantaflowGrid& grid) {
  try {
    grid.validate();
  } catch (const std::invalid_argument& e) {
    fail(path, e.what());
  }
  initializeOpenVdb();
  openvdb::FloatGrid::Ptr density;
  openvdb::Vec3SGrid::Ptr velocity;
  {
    // Read whole and checked before OpenVDB parses it (vdb_guard.h), never delay-loaded.
    const CheckedVdbFile file(path);
    density = readGrid<openvdb::FloatGrid>(file, "density", grid, path);
    velocity = readGrid<openvdb::Vec3SGrid>(file, "velocity", grid, path);
  }

  const glm::ivec3 n = grid.resolution;
  const std::size_t cells = std::size_t(n.x) * std::size_t(n.y) * std::size_t(n.z);
  MantaflowFrame frame;
  frame.density.resize(n);
  frame.velocity.resize(n);
  std::vector<openvdb::Vec3s> v(cells);
  std::vector<std::uint8_t> on(cells, 0);
  std::vector<std::uint8_t> bad(std::size_t(n.z), 0);  // per slab: a value is not finite
  forEachVoxel(*density, n, [&](int i, int j, int k, float d, bool) {
    if (!std::isfinite(d)) bad[std::size_t(k)] = 1;
    frame.density(i, j, k) = d;
  });
  forEachVoxel(*velocity, n, [&](int i, int j, int k, const openvdb::Vec3s& u, bool active) {
    if (!std::isfinite(u[0]) || !std::isfinite(u[1]) || !std::isfinite(u[2]))
      bad[std::size_t(k)] = 1;
    const std::size_t m = frame.density.index(i, j, k);
    v[m] = u;
    on[m] = active ? 1 : 0;
  });
  if (std::find(bad.begin(), bad.end(), 1) != bad.end())
    fail(path, "holds values that are not finite numbers (a broken bake)");

  if (velocity->getGridClass() == openvdb::GRID_STAGGERED)
    facesFromStaggered(v, on, n, frame.velocity);
  else
    facesFromCentred(v, on, n, frame.velocity);
  // Mantaflow cells per Mantaflow time unit to m/s along each world axis.
  for (int a = 0; a < 3; ++a) {
    const float scale = grid.cellSize[a] * grid.timeUnitsPerSecond;
    for (float& u : frame.velocity.component(a).values()) u *= scale;
  }
  return frame;
}

}  // namespace

MantaflowFrame readMantaflowFrame(const std::string& path, const MantaflowGrid& grid) {
  // Every failure names the file: OpenVDB's exceptions, a std::bad_alloc, anything.
  try {
    return readFrame(path, grid);
  } catch (const MantaflowFileError&) {
    throw;
  } catch (const std::bad_alloc&) {
    fail(path, "does not fit in memory");
  } catch (const std::exception& e) {
    fail(path, std::string("cannot be read: ") + e.what());
  }
}

void writeMantaflowVolume(const std::string& path, const MantaflowFrame& frame,
                          const MantaflowGrid& grid, int frameNumber) {
  initializeOpenVdb();
  const glm::ivec3 n = grid.resolution;
  if (frame.density.size() != n || frame.velocity.cells() != n)
    throw std::invalid_argument("Mantaflow volume: the frame is " + text(frame.density.size()) +
                                " cells; the grid is " + text(n));
  // Voxel (i,j,k) centred at origin + (i+½, j+½, k+½) * cellSize: scale, then translate.
  auto xform = openvdb::math::Transform::createLinearTransform(1.0);
  xform->preScale(openvdb::Vec3d(grid.cellSize.x, grid.cellSize.y, grid.cellSize.z));
  const glm::vec3 centre0 = grid.origin + 0.5f * grid.cellSize;
  xform->postTranslate(openvdb::Vec3d(centre0.x, centre0.y, centre0.z));

  // Cell-centred velocity for motion blur, only where there is smoke (as Plume's own frames).
  std::vector<openvdb::Vec3s> velocity(frame.density.count());
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const std::size_t m = frame.density.index(i, j, k);
        const glm::vec3 c =
            frame.density[m] != 0.f ? frame.velocity.cellCenter(i, j, k) : glm::vec3(0.f);
        velocity[m] = openvdb::Vec3s(c.x, c.y, c.z);
      }
  });
  openvdb::GridPtrVec grids;
  grids.push_back(denseFloatGrid("density", frame.density.data(), n, xform));
  grids.push_back(denseVectorGrid("velocity", velocity.data(), n, xform));
  openvdb::MetaMap meta;
  meta.insertMeta("creator", openvdb::StringMetadata("plume (Mantaflow cache)"));
  meta.insertMeta("frame", openvdb::Int32Metadata(frameNumber));
  writeGridsAtomic(path, grids, meta);
}

}  // namespace plume
