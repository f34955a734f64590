#pragma once
/// \file flame_raster.h
/// Flame particles into the VDB grids of a frame ([Structural Flames] §5.3: "ideally, the
/// deformed flames should be volume rendered directly"), for Blender's Principled Volume:
///   emission     Σ U P_i c_i w_i(v) / Δx³, vec3, W/m³ in Blender's light units (U =
///                emissionScale, the light unit; c_i the §5.1 colour, mean luminance 1): eq. 6's
///                incandescence as power, each channel splatted with fields/fire_raster's
///                conserving hat kernel, so Σ_v lum(emission) Δx³ = U Σ P_i ≈ U E (eq. 5)
///                whatever the particle count. One grid, not colour × strength: the product of
///                two interpolated grids darkens the sparse fringe, more so with fewer particles.
///                A volume renderer projects it to the camera itself (eq. 6's 1/4π((h/2)² + l²)).
///   color        mean base colour (§5.1) of the particles around the voxel (luminance ≈ 1)
///   density      opacity · Σ d_i mass_i w_i(v) / Δx³ ≈ opacity · (d/I)²: §5.3's opacity
///                "proportional to the relative brightness" — of the particle against the
///                flame's core (d = I), what is behind it being unknown before rendering
///   temperature  T_scale · (mean d_i/I of the particles around the voxel): Kelvin, fading to 0
///                where less than one particle's weight is present
///   flame        temperature / T_scale, clamped to [0, 1]
///   velocity     mean particle velocity (eq. 1), vec3, m/s: motion blur (§5.3)
/// The scalar grids come from rasterizeFire() (fields/fire_raster.h), color and velocity from
/// OpenVDB's points::rasterizeTrilinear on the same voxels (cell-centred, voxel (i,j,k) centred
/// at origin + (i + ½, j + ½, k + ½) Δx).

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
  float emissionScale = 1.f;        ///< U: Blender watts per watt of eq. 5 (the light unit)
  float opacity = 1.f;              ///< density where d = I (§5.3)
  /// m the velocity grid reaches past the particles, for motion blur (fields/velocity_extend.h):
  /// 0 keeps it on the particles' voxels; > 0 builds it 4× coarser, extended this far.
  float blurReach = 0.f;
  int threads = 0;                  ///< 0: all cores
  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
};

/// The six grids of a frame.
struct FlameGrids {
  openvdb::FloatGrid::Ptr density, temperature, flame;
  openvdb::Vec3SGrid::Ptr emission, color, velocity;
};

/// Rasterizes the particles (see the file comment).
FlameGrids rasterizeFlames(const FlameParticles& particles, const FlameRasterParams& params);

/// Writes the grids to `path` atomically (metadata creator "plume", frame `frame`).
/// Throws std::runtime_error naming the path.
void writeFlameVdb(const std::string& path, const FlameGrids& grids, int frame);

}  // namespace plume
