#pragma once
/// \file vdb_frame.h
/// The per-frame VDB of a bake: grids `density`, `temperature`, `flame` (when burning) and
/// `velocity`, named so Blender's Principled Volume reads them with no attribute nodes.

#include "solver/smoke_solver.h"

#include <string>
#include <vector>

namespace plume {

/// Writes the solver's current state to `path` as a VDB with fog-volume float grids `density`
/// (smoke density + soot), `temperature`, `flame` (only when params().combustion) and a
/// cell-centred vec3 grid `velocity` (only in voxels with density or flame, or in every voxel
/// when `velocityEverywhere`: a domain read as a wind field, [Structural Flames] §6.1). Voxel
/// (i,j,k) is centred at origin + (i+½, j+½, k+½) Δx in
/// world space. Zero voxels are not stored. Written to `path + ".tmp"` and renamed, so a killed
/// bake never leaves a half file. Throws std::runtime_error with the path on failure.
void writeVdbFrame(const std::string& path, const SmokeSolver& solver,
                   bool velocityEverywhere = false);

/// A grid read back from a VDB file, as a dense box.
struct DenseGrid {
  std::string name;
  glm::ivec3 min{0};   ///< index of the first voxel of the dense box
  glm::ivec3 size{0};  ///< box size in voxels (0 when the grid is empty)
  int components = 1;  ///< 1 for float grids, 3 for vec3 grids
  float voxelSize = 1.f;                ///< along x (Plume's own grids are cubic)
  glm::vec3 voxelSizes{1.f};            ///< per axis (a Mantaflow domain's cells are not cubic)
  bool axisAligned = true;              ///< the index-to-world map is a diagonal scale + shift
  glm::vec3 worldOfVoxelZero{0.f};  ///< world position of voxel (0,0,0)'s centre
  std::vector<float> values;        ///< x fastest, components interleaved
};

/// Names of the grids in a VDB file. Throws std::runtime_error if the file cannot be read.
std::vector<std::string> vdbGridNames(const std::string& path);

/// Reads one float or vec3 grid as a dense box. Throws std::runtime_error if the file or grid is
/// missing or of another type.
DenseGrid readVdbGrid(const std::string& path, const std::string& name);

}  // namespace plume
