#pragma once
/// \file flame_raster.h
/// Flame particles into the VDB grids of a frame (structural_flames.txt §5.3: "ideally, the
/// deformed flames should be volume rendered directly"), for Blender's Principled Volume:
///   density      Σ mass_i w_i(v) / Δx³: the particles' splatted mass (fields/fire_raster's
///                conserving hat kernel), so the grid approximates eq. 4's d(x) in world space
///                whatever the particle count
///   temperature  T_scale · (mean d_i/I of the particles around the voxel): Kelvin for
///                Principled Volume's blackbody, fading to 0 where less than one particle's
///                weight is present
///   flame        temperature / T_scale, clamped to [0, 1]: emission strength
///   color        mean base colour (§5.1), vec3 (Principled Volume's Color attribute)
///   velocity     mean particle velocity, vec3, for motion blur (§5.3)
/// density/temperature/flame come from rasterizeFire() (fields/fire_raster.h), color and
/// velocity from OpenVDB's points::rasterizeTrilinear on the same voxels (cell-centred,
/// voxel (i,j,k) centred at origin + (i + ½, j + ½, k + ½) Δx).

#include "flames/flame_shape.h"

#include <openvdb/openvdb.h>

#include <glm/glm.hpp>

#include <string>

namespace plume {

/// Settings of the flame rasterization.
struct FlameRasterParams {
  float voxelSize = 0.01f;          ///< Δx, m
  glm::vec3 origin{0.f};            ///< the voxel grid's origin
  float temperatureScale = 1500.f;  ///< K at d = I
  int threads = 0;                  ///< 0: all cores
  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
};

/// The five grids of a frame.
struct FlameGrids {
  openvdb::FloatGrid::Ptr density, temperature, flame;
  openvdb::Vec3SGrid::Ptr color, velocity;
};

/// Rasterizes the particles (see the file comment).
FlameGrids rasterizeFlames(const FlameParticles& particles, const FlameRasterParams& params);

/// Writes the grids to `path` atomically (metadata creator "plume", frame `frame`).
/// Throws std::runtime_error naming the path.
void writeFlameVdb(const std::string& path, const FlameGrids& grids, int frame);

}  // namespace plume
