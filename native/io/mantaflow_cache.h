#pragma once
/// \file mantaflow_cache.h
/// One frame of a Blender (3.4) Mantaflow gas cache, `<cache>/data/fluid_data_####.vdb`, read
/// as the fields that carry streakline tracers ([Smoke Surfaces] §3.2: particles "advected by
/// the velocity field"), and written back as a Plume volume frame.
///
/// What Blender 3.4 writes (checked on real bakes, see the add-on's mantaflow_trace.py):
/// - grids `density` (float, fog volume), `velocity` (vec3s, class *staggered*: voxel (i,j,k)
///   holds u on the face between cells i-1 and i, v and w likewise, as MacGrid3), plus
///   `temperature`, `flame`, `shadow`; 16-bit half floats unless the cache depth is 32;
/// - one uniform linear transform, voxel size = longest domain side / resolution_max, no
///   translation: it is *not* the world placement. Blender stretches the base_res cells over the
///   domain object's bounding box, so world cells are size_a / base_res_a per axis (not cubic);
/// - grid metadata `file_base_resolution` = base_res;
/// - voxels only where density > the domain's Clipping (1e-6 by default; > 0 even at 0): the
///   velocity is absent (zero) outside the smoke;
/// - velocity in Mantaflow cells per Mantaflow time unit; one second is 2.5 time units
///   (Blender: frame length = 0.1 * (25 / fps) * time_scale), so u [m/s] = value * cell size * 2.5.

#include <glm/glm.hpp>
#include <string>

#include "core/grid3.h"
#include "core/mac_grid3.h"

namespace plume {

/// Mantaflow time units per (simulated) second: frame length 0.1 * 25 / fps * time_scale.
constexpr float kMantaflowTimeUnitsPerSecond = 2.5f;

/// Where a Mantaflow domain's cells lie in world space: base_res cells, the corner of cell
/// (0,0,0) at `origin`, cell size per axis (the domain's box stretched over base_res cells).
struct MantaflowGrid {
  glm::ivec3 resolution{0};
  glm::vec3 origin{0.f};
  glm::vec3 cellSize{1.f};
  float timeUnitsPerSecond = kMantaflowTimeUnitsPerSecond;

  /// Voxel size of the cache's VDB transform: the longest side over the longest resolution.
  float vdbVoxelSize() const;
  /// World position of cell coordinates c (cell (i,j,k) spans [i, i+1] x [j, j+1] x [k, k+1]).
  glm::vec3 indexToWorld(glm::vec3 c) const { return origin + c * cellSize; }
  glm::vec3 worldToIndex(glm::vec3 w) const { return (w - origin) / cellSize; }
  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
};

/// Largest accepted Mantaflow resolution per axis (Blender's own limit is 10000 per axis, but
/// dense frames beyond this do not fit in memory).
constexpr int kMaxMantaflowResolution = 2048;

/// The fields of one Mantaflow frame on its base grid: density at cell centres and face
/// velocities in m/s along the world axes (what StreakTracer::step takes, index space aside).
struct MantaflowFrame {
  ScalarGrid density;
  MacGrid3 velocity;
  /// An empty domain (zero density and velocity): the state before the first cached frame.
  static MantaflowFrame empty(glm::ivec3 resolution);
  /// Largest |u_a| / cellSize_a over all faces: cells per second.
  float maxCellsPerSecond(const MantaflowGrid& grid) const;
};

/// Reads `density` and `velocity` of a Mantaflow VDB frame onto `grid`. A staggered velocity
/// is copied face by face; a cell-centred one (another writer) is averaged onto the faces.
/// Faces the file does not hold because Mantaflow clipped the voxel (no smoke there) but whose
/// lower cell is stored take the value of that cell's lower face (constant extrapolation over
/// one face), so the flow does not stall at the smoke's upper edges; the top faces of the last
/// cells (outside Mantaflow's grid) do the same. Throws std::runtime_error naming the file when
/// it is missing or unreadable, a grid is missing or of another type, the transform, voxel size
/// or base resolution differ from `grid`, a voxel lies outside it, or a value is not finite.
MantaflowFrame readMantaflowFrame(const std::string& path, const MantaflowGrid& grid);

/// Writes a frame as a Plume volume frame (vdb_frame.h names): fog-volume `density` and the
/// cell-centred `velocity` (m/s, only where there is smoke) with the world transform of `grid`
/// (cell (i,j,k) centred at origin + (i+½, j+½, k+½) * cellSize), atomically. Throws
/// std::runtime_error naming the path on failure.
void writeMantaflowVolume(const std::string& path, const MantaflowFrame& frame,
                          const MantaflowGrid& grid, int frameNumber);

}  // namespace plume
