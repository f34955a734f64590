#pragma once
/// \file velocity_extend.h
/// A velocity grid extended beyond the voxels that hold it, for volume motion blur. Cycles blurs
/// a volume by looking every grid up at x − τ u(x) over the shutter τ ([Structural Flames]
/// §5.3: "motion blurred using the instantaneous velocities"): where u is 0 — just outside the
/// flame — nothing is displaced, so a fast flame's outline would not blur at all. Extending u
/// by the distance the flame moves during the shutter lets the blur reach past it.
///
/// The extension is built on a coarser grid (`coarsen` × the voxel size: the velocity is smooth
/// and the extension's cost grows with the cube of its reach in voxels): the particles'
/// velocities rasterized there (points::rasterizeTrilinear), then dilated one voxel at a time,
/// each new voxel taking the mean of its already-set neighbours (26-neighbourhood), until
/// `reach` metres are covered. Deterministic (every voxel reads only the previous layer).

#include <openvdb/openvdb.h>

#include <glm/glm.hpp>

#include <vector>

namespace plume {

/// Settings of the extension.
struct VelocityExtendParams {
  float voxelSize = 0.01f;  ///< Δx of the coarse grid, m (cell-centred like the others)
  glm::vec3 origin{0.f};
  float reach = 0.f;        ///< m to extend by (0: the rasterized velocity only)
  int maxLayers = 32;       ///< at most this many dilation steps
};

/// The velocity grid "velocity" of particles at `positions` with `velocities` (m/s).
openvdb::Vec3SGrid::Ptr extendedVelocity(const std::vector<glm::vec3>& positions,
                                         const std::vector<glm::vec3>& velocities,
                                         const VelocityExtendParams& params);

}  // namespace plume
