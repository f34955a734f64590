#pragma once
/// \file emitters.h
/// Source and obstacle meshes turned into solver cells with OpenVDB's mesh-to-volume tools.

#include "core/grid3.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace plume {

/// A Blender mesh snapshot: object-local vertices and triangles, and its object-to-world matrix
/// at the frame being simulated and at the next frame (the difference is the object's motion).
struct EmitterMesh {
  std::string name;  ///< Blender object name, used in error messages
  std::vector<glm::vec3> vertices;
  std::vector<glm::ivec3> triangles;
  glm::mat4 matrix{1.f};      ///< local -> world at frame f
  glm::mat4 matrixNext{1.f};  ///< local -> world at frame f + 1
};

/// The grid an emitter is voxelized into.
struct GridFrame {
  glm::ivec3 resolution{0};
  float cellSize = 1.f;
  glm::vec3 origin{0.f};
  float frameDt = 1.f / 24.f;  ///< time between matrix and matrixNext
};

/// Cells covered by an emitter (linear indices i + nx*(j + ny*k), ascending) and the velocity of
/// the emitter's own motion at each of those cells, (matrixNext * matrix^-1 * x - x) / frameDt.
struct CellSet {
  std::vector<std::uint32_t> cells;
  std::vector<glm::vec3> velocity;
};

/// Source cells: cells whose centre is inside the closed mesh or within half a cell of its
/// surface, so that open or flat meshes (a plane, a disc) still emit.
CellSet voxelizeSource(const EmitterMesh& mesh, const GridFrame& grid);

/// Obstacle cells: cells whose centre is inside the mesh (OpenVDB meshToLevelSet, φ < 0).
/// Throws std::invalid_argument naming the object when the mesh is not closed and manifold
/// (every edge must be shared by exactly two triangles) or is empty.
CellSet voxelizeObstacle(const EmitterMesh& mesh, const GridFrame& grid);

/// Number of edges not shared by exactly two triangles (0 for a closed manifold mesh).
std::size_t countNonManifoldEdges(const std::vector<glm::ivec3>& triangles);

}  // namespace plume
