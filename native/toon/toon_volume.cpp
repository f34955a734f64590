/// \file toon_volume.cpp
/// Plume volume frames to toon fields: dense boxes from io/vdb_frame placed on the bake's grid.

#include "toon/toon_volume.h"

#include "core/parallel.h"
#include "io/mac_faces.h"
#include "io/vdb_frame.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace plume {
namespace {

/// Relative tolerance on voxel size and placement (floats written from the same settings).
constexpr float kTolerance = 1e-4f;

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error("volume file '" + path + "': " + what);
}

std::string text(glm::ivec3 v) {
  return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

/// Checks that the grid's voxels are the bake's cells and lie inside the grid.
void checkPlacement(const DenseGrid& g, const GridFrame& grid, const std::string& path) {
  const float cell = grid.cellSize;
  if (std::abs(g.voxelSize - cell) > kTolerance * cell)
    fail(path, "grid '" + g.name + "' has voxel size " + std::to_string(g.voxelSize) +
                   "; the bake's cell size is " + std::to_string(cell) +
                   " (another bake or resolution?)");
  const glm::vec3 centre = grid.origin + glm::vec3(0.5f * cell);
  const float scale = std::max(cell, glm::length(centre));
  if (glm::length(g.worldOfVoxelZero - centre) > kTolerance * scale)
    fail(path, "grid '" + g.name + "' is not placed on the bake's domain (voxel 0 at another "
                                   "position: was the domain moved after the bake?)");
  if (g.size == glm::ivec3(0)) return;
  if (glm::any(glm::lessThan(g.min, glm::ivec3(0))) ||
      glm::any(glm::greaterThan(g.min + g.size, grid.resolution)))
    fail(path, "grid '" + g.name + "' has voxels from " + text(g.min) + " to " +
                   text(g.min + g.size - 1) + ", outside the bake's grid " + text(grid.resolution));
  for (float v : g.values)
    if (!std::isfinite(v)) fail(path, "grid '" + g.name + "' holds a non-finite value");
}

/// Component c of the box value at grid cell (i,j,k), or 0 outside the box.
float boxValue(const DenseGrid& g, glm::ivec3 p, int c) {
  const glm::ivec3 q = p - g.min;
  if (glm::any(glm::lessThan(q, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(q, g.size)))
    return 0.f;
  const std::size_t m =
      std::size_t(q.x) + std::size_t(g.size.x) * (std::size_t(q.y) + std::size_t(g.size.y) * std::size_t(q.z));
  return g.values[m * std::size_t(g.components) + std::size_t(c)];
}

void denseScalar(const DenseGrid& g, glm::ivec3 n, ScalarGrid& out) {
  out.resize(n, 0.f);
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) out(i, j, k) = boxValue(g, {i, j, k}, 0);
  });
}

/// Whether cell p holds a velocity (a stored, non-zero vector).
bool holdsVelocity(const DenseGrid& g, glm::ivec3 p) {
  return boxValue(g, p, 0) != 0.f || boxValue(g, p, 1) != 0.f || boxValue(g, p, 2) != 0.f;
}

/// Faces from the cell-centred velocities, as Plume stores them (only where there is smoke).
void faceVelocities(const DenseGrid& g, glm::ivec3 n, MacGrid3& mac) {
  mac.resize(n);
  facesFromCentres(
      mac, n, [&](glm::ivec3 p) { return holdsVelocity(g, p); },
      [&](glm::ivec3 p, int a) { return boxValue(g, p, a); });
}

/// The file's voxel coordinates of world position w.
glm::vec3 voxelOf(const DenseGrid& g, glm::vec3 w) { return (w - g.worldOfVoxelZero) / g.voxelSizes; }

/// Trilinear interpolation of component c at voxel coordinates q over the voxels for which
/// use(voxel) holds, the weights renormalised over them; 0 when none is used.
template <typename Use>
float trilinear(const DenseGrid& g, glm::vec3 q, int c, const Use& use) {
  const glm::vec3 fl = glm::floor(q);
  const glm::ivec3 p0(fl);
  const glm::vec3 t = q - fl;
  float sum = 0.f, weight = 0.f;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::ivec3 d(corner & 1, (corner >> 1) & 1, corner >> 2);
    const glm::ivec3 p = p0 + d;
    if (!use(p)) continue;
    const float w = (d.x ? t.x : 1.f - t.x) * (d.y ? t.y : 1.f - t.y) * (d.z ? t.z : 1.f - t.z);
    sum += w * boxValue(g, p, c);
    weight += w;
  }
  return weight > 0.f ? sum / weight : 0.f;
}

/// Checks that a grid to be resampled is axis-aligned, finite and inside `grid`'s box.
void checkResampled(const DenseGrid& g, const GridFrame& grid, const std::string& path) {
  if (!g.axisAligned || !(glm::all(glm::greaterThan(g.voxelSizes, glm::vec3(0.f)))))
    fail(path, "grid '" + g.name + "' is not an axis-aligned grid of positive voxel sizes");
  for (float v : g.values)
    if (!std::isfinite(v)) fail(path, "grid '" + g.name + "' holds a non-finite value");
  if (g.size == glm::ivec3(0)) return;
  const glm::vec3 lo = g.worldOfVoxelZero + glm::vec3(g.min) * g.voxelSizes;
  const glm::vec3 hi = g.worldOfVoxelZero + glm::vec3(g.min + g.size - 1) * g.voxelSizes;
  const glm::vec3 box0 = grid.origin - 0.5f * grid.cellSize;
  const glm::vec3 box1 = grid.origin + (glm::vec3(grid.resolution) + 0.5f) * grid.cellSize;
  if (glm::any(glm::lessThan(lo, box0)) || glm::any(glm::greaterThan(hi, box1)))
    fail(path, "grid '" + g.name + "' has voxels outside the domain's box (was the domain "
                                   "moved or resized after the bake?)");
}

void resampleScalar(const DenseGrid& g, const GridFrame& grid, ScalarGrid& out) {
  const glm::ivec3 n = grid.resolution;
  out.resize(n, 0.f);
  const auto all = [](glm::ivec3) { return true; };
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i)
        out(i, j, k) = trilinear(g, voxelOf(g, grid.origin + (glm::vec3(i, j, k) + 0.5f) * grid.cellSize), 0, all);
  });
}

}  // namespace

ToonFields resampleToonFields(const std::string& path, const GridFrame& grid) {
  validateToonGrid(grid);
  const std::vector<std::string> names = vdbGridNames(path);
  ToonFields f;
  for (const char* name : {"density", "temperature"}) {
    if (std::string(name) == "temperature" &&
        std::find(names.begin(), names.end(), name) == names.end())
      continue;
    const DenseGrid d = readVdbGrid(path, name);
    if (d.components != 1) fail(path, std::string("grid '") + name + "' must be a float grid");
    checkResampled(d, grid, path);
    resampleScalar(d, grid, name == std::string("density") ? f.density : f.temperature);
  }
  const DenseGrid v = readVdbGrid(path, "velocity");
  if (v.components != 3) fail(path, "grid 'velocity' must be a vec3 grid");
  checkResampled(v, grid, path);
  f.velocity.resize(grid.resolution);
  const auto held = [&](glm::ivec3 p) { return holdsVelocity(v, p); };
  fillFaces(f.velocity, [&](glm::ivec3 face, glm::ivec3, int a) {
    glm::vec3 centre = (glm::vec3(face) + 0.5f) * grid.cellSize;
    centre[a] -= 0.5f * grid.cellSize;  // the face below cell `face` on axis a
    return trilinear(v, voxelOf(v, grid.origin + centre), a, held);
  });
  return f;
}

ToonFields readToonFields(const std::string& path, const GridFrame& grid) {
  validateToonGrid(grid);
  const std::vector<std::string> names = vdbGridNames(path);
  const bool hasTemperature = std::find(names.begin(), names.end(), "temperature") != names.end();
  ToonFields f;
  const glm::ivec3 n = grid.resolution;
  {
    const DenseGrid d = readVdbGrid(path, "density");
    if (d.components != 1) fail(path, "grid 'density' must be a float grid");
    checkPlacement(d, grid, path);
    denseScalar(d, n, f.density);
  }
  if (hasTemperature) {
    const DenseGrid t = readVdbGrid(path, "temperature");
    if (t.components != 1) fail(path, "grid 'temperature' must be a float grid");
    checkPlacement(t, grid, path);
    denseScalar(t, n, f.temperature);
  }
  const DenseGrid v = readVdbGrid(path, "velocity");
  if (v.components != 3) fail(path, "grid 'velocity' must be a vec3 grid");
  checkPlacement(v, grid, path);
  faceVelocities(v, n, f.velocity);
  return f;
}

const ToonFields& ToonVolumeCache::fields(const std::string& path) {
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  const std::filesystem::file_time_type time = std::filesystem::last_write_time(path, error);
  if (error) fail(path, "cannot be read: " + error.message());
  for (int e = 0; e < 2; ++e)
    if (!mEntries[e].path.empty() && mEntries[e].path == path && mEntries[e].size == size &&
        mEntries[e].time == time) {
      mRecent = e;
      return mEntries[e].fields;
    }
  Entry& slot = mEntries[1 - mRecent];
  slot.path.clear();  // stays empty if the read throws
  slot.fields = mResample ? resampleToonFields(path, mGrid) : readToonFields(path, mGrid);
  slot.path = path;
  slot.size = size;
  slot.time = time;
  mRecent = 1 - mRecent;
  return slot.fields;
}

}  // namespace plume
