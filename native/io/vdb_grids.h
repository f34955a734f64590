#pragma once
/// \file vdb_grids.h
/// OpenVDB building blocks shared by the VDB frame writers (vdb_frame.cpp, mantaflow_cache.cpp):
/// dense solver arrays to sparse grids, and the atomic, verified file write. Includes OpenVDB,
/// so only io/ sources include it.

#include <openvdb/openvdb.h>

#include <glm/glm.hpp>
#include <string>

namespace plume {

/// openvdb::initialize(), once per process (thread-safe).
void initializeOpenVdb();

/// The transform of Plume's frame VDBs: voxel size Δx = `cellSize`, voxel (i,j,k) centred at
/// origin + (i + 1/2, j + 1/2, k + 1/2) Δx (cell (i,j,k) of the solver is voxel (i,j,k)).
openvdb::math::Transform::Ptr cellCenteredTransform(float cellSize, glm::vec3 origin);

/// A fog-volume float grid `name` holding the non-zero values of `values` (x-fastest,
/// n.x * n.y * n.z, solver layout: value (i,j,k) at voxel (i,j,k)) with transform `xform`.
openvdb::FloatGrid::Ptr denseFloatGrid(const std::string& name, const float* values, glm::ivec3 n,
                                       const openvdb::math::Transform::Ptr& xform);

/// A cell-centred vector grid `name` (class unknown, contravariant relative: a velocity)
/// holding the non-zero vectors of `values` (x-fastest, n.x * n.y * n.z).
openvdb::Vec3SGrid::Ptr denseVectorGrid(const std::string& name, const openvdb::Vec3s* values,
                                        glm::ivec3 n, const openvdb::math::Transform::Ptr& xform);

/// Writes `grids` with file metadata `meta` to `path + ".tmp"` (Blosc when available), reads
/// the grid descriptors back (io::File::write does not report a full disk), then renames it to
/// `path`, so a killed writer never leaves a half file. Throws std::runtime_error with the path.
void writeGridsAtomic(const std::string& path, const openvdb::GridPtrVec& grids,
                      const openvdb::MetaMap& meta);

}  // namespace plume
