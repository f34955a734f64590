#pragma once
/// \file splat_radius.h
/// The splat radius of every particle from the local particle spacing (fields/fire_raster.h):
/// particles are seeded at Δx/2 ([Graph Fire Synthesis] §4.2) and spread apart as they rise,
/// so a kernel of one voxel leaves gaps between old particles (speckle, detached blobs). The
/// radius grows with the spacing so that neighbouring kernels overlap as on the seeding lattice.
///
/// Spacing from a density estimate on a coarse grid of cells C = 4 Δx (the point leaves' 8³
/// voxels hold 2³ of them): n_c particles in cell c; n(x) the trilinear interpolation of n_c
/// between cell centres; the spacing
///   s(x) = (C³ / n(x))^(1/3)                   (voxels; 8 particles per voxel: s = 1/2)
///   r_p  = clamp(κ s(x_p), 1, r_max)           (voxels)
/// A tent of half-width r = s sums to a constant over a lattice of spacing s (a partition of
/// unity), hence κ = 1; r = 1 is the trilinear hat, which dense (young) fire keeps.
///
/// The count is blind to one gap: flow-graph fire emits a group (a sheet of particles Δx/2
/// apart) every node step Δt_n, so consecutive sheets are |u| Δt_n apart along the flow while
/// each is dense (dark bands across a fast flame). With the particles' velocities and Δt_n the
/// radius also covers that distance:
///   r_p  = clamp(max(κ s(x_p), |u_p| Δt_n / Δx), 1, r_max)
/// Every point's radius depends only on the counts and its own velocity, so it is the same at
/// any thread count.

#include <openvdb/points/PointDataGrid.h>

#include <string>
#include <vector>

namespace plume {

/// Settings of the estimate.
struct SplatRadiusParams {
  float spacingScale = 1.f;  ///< κ (0: every radius is 1, the trilinear hat)
  float maxRadius = 4.f;     ///< r_max, voxels (>= 1)
  float sheetInterval = 0.f; ///< Δt_n, s, between emitted sheets (0: no sheet term)
  float voxelSize = 1.f;     ///< Δx, m (for |u| Δt_n / Δx)
};

/// Adds a float attribute `name` (r_p, index-space voxels) to every point of `tree` and returns
/// ceil(max r_p) of every point leaf, in the tree's leaf order (LeafManager order). The sheet
/// term reads the Vec3f attribute `velocity` (m/s) when the points have one.
std::vector<int> appendSplatRadius(openvdb::points::PointDataTree& tree, const SplatRadiusParams& params,
                                   const std::string& name, const std::string& velocity = "velocity");

}  // namespace plume
