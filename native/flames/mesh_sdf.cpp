/// \file mesh_sdf.cpp
#include "flames/mesh_sdf.h"

#include "io/vdb_grids.h"
#include "solver/emitters.h"

#include <openvdb/tools/MeshToVolume.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace plume {

namespace {

[[noreturn]] void fail(const std::string& name, const std::string& what) {
  throw std::invalid_argument("obstacle '" + name + "' " + what);
}

}  // namespace

MeshSdfGrid meshSignedDistance(const std::vector<glm::vec3>& vertices,
                               const std::vector<glm::ivec3>& triangles, double cellSize,
                               double padding, const std::string& name) {
  if (!(std::isfinite(cellSize) && cellSize > 0.0))
    fail(name, "needs a voxel size > 0 (got " + std::to_string(cellSize) + ")");
  if (!(std::isfinite(padding) && padding >= 0.0)) fail(name, "needs a padding >= 0");
  if (vertices.empty() || triangles.empty()) fail(name, "is empty: it has no triangles");
  const std::size_t open = countNonManifoldEdges(triangles);
  if (open != 0) {
    std::ostringstream s;
    s << "is not a closed manifold mesh: " << open << " open or non-manifold edges (obstacles must "
      << "be watertight)";
    fail(name, s.str());
  }
  for (const glm::ivec3& t : triangles)
    for (int c = 0; c < 3; ++c)
      if (t[c] < 0 || std::size_t(t[c]) >= vertices.size()) fail(name, "has a triangle index out of range");
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
  for (const glm::vec3& v : vertices) {
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) fail(name, "has a non-finite vertex");
    lo = glm::min(lo, glm::dvec3(v));
    hi = glm::max(hi, glm::dvec3(v));
  }
  MeshSdfGrid out;
  out.cellSize = cellSize;
  out.origin = lo - padding;
  const glm::dvec3 extent = (hi + padding - out.origin) / cellSize;
  const glm::ivec3 n(std::max(1, int(std::ceil(extent.x))), std::max(1, int(std::ceil(extent.y))),
                     std::max(1, int(std::ceil(extent.z))));
  if (double(n.x) * n.y * n.z > double(kMaxMeshSdfCells)) {
    std::ostringstream s;
    s << "needs " << n.x << "x" << n.y << "x" << n.z << " voxels of " << cellSize
      << " m (at most 2^24): raise the voxel size";
    fail(name, s.str());
  }
  initializeOpenVdb();
  const auto xform = cellCenteredTransform(float(cellSize), glm::vec3(out.origin));
  std::vector<openvdb::Vec3s> points(vertices.size());
  for (std::size_t i = 0; i < vertices.size(); ++i)
    points[i] = xform->worldToIndex(openvdb::Vec3d(vertices[i].x, vertices[i].y, vertices[i].z));
  std::vector<openvdb::Vec3I> tris(triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i)
    tris[i] = openvdb::Vec3I(triangles[i].x, triangles[i].y, triangles[i].z);
  // Index-space points with a unit transform, then world units: the interior band spans the
  // whole grid so every inside cell has its (negative) distance, not just the surface band.
  const float inside = float(std::max({n.x, n.y, n.z}));
  const auto sdf = openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(
      *openvdb::math::Transform::createLinearTransform(1.0), points, tris,
      std::vector<openvdb::Vec4I>(), /*exBandWidth=*/3.f, /*inBandWidth=*/inside);
  out.values.resize(n, 0.f);
  const auto acc = sdf->getConstAccessor();
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i)
        out.values[out.values.index(i, j, k)] = acc.getValue(openvdb::Coord(i, j, k)) * float(cellSize);
  return out;
}

}  // namespace plume
