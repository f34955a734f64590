#pragma once
/// \file mesh_sdf.h
/// Obstacles of structural flames as voxels ([Structural Flames] §6.1: "we approximate the
/// object as a series of solid voxels"): the signed distance φ of a closed mesh on a dense
/// cell-centred grid, from OpenVDB's mesh-to-volume, for GridSdf (obstacle_sdf.h).

#include "core/grid3.h"

#include <glm/glm.hpp>

#include <string>
#include <vector>

namespace plume {

/// φ on cells (i,j,k) centred at origin + (i + ½, j + ½, k + ½)·cellSize: < 0 inside (m).
struct MeshSdfGrid {
  ScalarGrid values;
  double cellSize = 0.0;
  glm::dvec3 origin{0.0};
};

/// Most cells a mesh SDF grid may have (2^24, 64 MB of floats).
constexpr std::size_t kMaxMeshSdfCells = std::size_t(1) << 24;

/// §6.1: the signed distance of the closed mesh (world-space vertices, triangles) over its
/// bounding box grown by `padding` (m), on cells of `cellSize` (m). Exact near the surface
/// (OpenVDB's narrow band of 3 voxels outside), filled through the whole inside, +3 cells
/// beyond the band. Throws std::invalid_argument naming `name` for an empty, open or
/// non-manifold mesh, a cell size that is not finite and > 0, or more than kMaxMeshSdfCells.
MeshSdfGrid meshSignedDistance(const std::vector<glm::vec3>& vertices,
                               const std::vector<glm::ivec3>& triangles, double cellSize,
                               double padding, const std::string& name);

}  // namespace plume
