#pragma once
/// \file fire_raster.h
/// Particles into VDB grids `density`, `temperature` and `flame`, shared by the two fire
/// pipelines: flow-graph fire rasterizes its synthesized particles with it
/// ([Graph Fire Synthesis] §5.3; DESIGN.md: "rasterization of particles into VDB grids with
/// OpenVDB's point tools"), structural flames its scalar grids (flames/flame_raster.cpp). On the
/// bake's voxels, written as a frame VDB (io/vdb_grids.h).
///
/// The particles become an OpenVDB PointDataGrid (attributes `density`, `temperature`,
/// `velocity`) and are rasterized with OpenVDB's point transfer framework
/// (openvdb/points/PointTransfer.h, points::rasterize; OpenVDB 10 has no density kernel of its
/// own, only the trilinear hat and SDF spheres) in one pass into four accumulators per voxel v.
/// Each particle's kernel is a separable tent of half-width r_p voxels, r_p from the local
/// particle spacing (fields/splat_radius.h: 1 voxel, the trilinear hat of
/// points::rasterizeTrilinear, where particles are as dense as when seeded; up to r_max where
/// they have spread apart, or where the sheets flow-graph fire emits every node step have been
/// drawn apart along a fast flow, so old particles do not leave gaps):
///   k_p(v) = Π_axes max(0, 1 - |v_a - x_a| / r_p)  (peak 1 at the particle)
///   w_p(v) = k_p(v) / Σ_v' k_p(v')                 (weights that sum to 1 over the voxels)
///   density     ρ_v = Σ_p w_p(v) R_p V_p / Δx³   (splatted, not averaged: Σ_v ρ_v Δx³ = Σ_p R_p V_p,
///                                                the particles' mass is conserved; V_p is the
///                                                volume a particle stands for)
///   temperature T_v = T_amb + Σ_p k_p(v) (T_p - T_amb) / max(Σ_p k_p(v), 1)
///               (the mean of the particles around the voxel, fading to ambient where less than
///               one particle's peak weight is present, so the fire has no hard edge and a lone
///               particle keeps its temperature at its centre whatever its radius)
///   flame       f_v = clamp((T_v - T_ignition) / (T_max - T_ignition), 0, 1)
///               (temperature above the ignition threshold mapped to [0, 1])
///   velocity    (when the particles have velocities) Σ_p k_p(v) u_p / Σ_p k_p(v), m/s, their
///               mean around the voxel: Cycles' volume motion blur
/// Voxel (i,j,k) is centred at origin + (i + 1/2, j + 1/2, k + 1/2) Δx, as in the bake's frames.
/// Deterministic: every voxel sums its particles in the same order at any thread count.

#include <openvdb/openvdb.h>

#include <glm/glm.hpp>

#include <cstddef>
#include <string>

namespace plume {

/// Settings of the rasterization.
struct FireRasterParams {
  float voxelSize = 1.f / 32.f;  ///< Δx: the bake's cell size
  glm::vec3 origin{0.f};         ///< the bake's domain origin
  /// V_p, m³: the volume each particle stands for; 0 means (Δx/2)³, the volume of a seed
  /// (§4.2 seeds at spacing Δx/2), so a freshly seeded cell of density R rasterizes to R.
  float particleVolume = 0.f;
  float ambientTemperature = 0.f;   ///< T_amb (the solver's ambient_temperature)
  float ignitionTemperature = 1.f;  ///< T at which flame begins (flame 0)
  float maxTemperature = 4.f;       ///< T at which flame is 1 (the solver's max_temperature)
  /// κ: the splat radius is κ times the local particle spacing (fields/splat_radius.h), at
  /// least one voxel; 0: the trilinear hat of one voxel for every particle.
  float spacingScale = 1.f;
  float maxSplatRadius = 4.f;       ///< r_max, voxels, in [1, 8]
  /// Δt_n, s: the particles were emitted in sheets this far apart in time (flow-graph fire's
  /// node step); with velocities, the splat radius also covers |u| Δt_n (0: not).
  float sheetInterval = 0.f;
  int threads = 0;                  ///< worker threads (0: all cores)
  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
};

/// Particles to rasterize (arrays of `count` entries, world positions).
struct FireParticleView {
  const glm::vec3* positions = nullptr;
  const float* density = nullptr;
  const float* temperature = nullptr;
  std::size_t count = 0;
  const glm::vec3* velocities = nullptr;  ///< m/s, optional: the `velocity` grid
};

/// The three grids of one synthesized frame (fog volumes; background 0, T_amb for temperature).
struct FireGrids {
  openvdb::FloatGrid::Ptr density, temperature, flame;
  openvdb::Vec3SGrid::Ptr velocity;  ///< null when the particles have no velocities
};

/// Rasterizes the particles (see the file comment). Non-finite particles are skipped.
FireGrids rasterizeFire(const FireParticleView& particles, const FireRasterParams& params);

/// Writes the grids to `path` as a frame VDB (metadata creator "plume", frame `frame`),
/// atomically (io/vdb_grids.h). Throws std::runtime_error naming the path.
void writeFireVdb(const std::string& path, const FireGrids& grids, int frame);

}  // namespace plume
