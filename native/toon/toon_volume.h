#pragma once
/// \file toon_volume.h
/// A Plume volume frame (`volume_####.vdb`, io/vdb_frame.h) read back as the fields that drive
/// the toon particles ([Cartoon Smoke] §2.1: the particles need only the simulator's output),
/// so the add-on never copies grids through Python.

#include "toon/toon_fields.h"

#include <cstdint>
#include <filesystem>
#include <string>

namespace plume {

/// Reads grids `density`, `velocity` (cell-centred vec3, m/s) and, when present, `temperature`
/// of a Plume volume frame onto `grid` (the bake's resolution, cell size and origin, from its
/// manifest). Voxels the file does not hold are 0. A face velocity is the mean of the two cells
/// beside it that hold a velocity (Plume stores velocity only where there is smoke), or the one of
/// them that does. Throws std::runtime_error naming the path when the file or a grid is missing
/// or unreadable, the voxel size or placement differ from `grid`, a voxel lies outside it or a
/// value is not finite; std::invalid_argument for a bad grid.
ToonFields readToonFields(const std::string& path, const GridFrame& grid);

/// readToonFields for a volume whose voxels are not the cells of `grid`: a traced Mantaflow
/// domain's frames, whose cells are not cubic (io/mantaflow_cache.h). Each cell centre of `grid`
/// takes the trilinear interpolation of the file's density (and temperature), 0 outside its
/// voxels; each face takes the trilinear interpolation of the velocities over those of the 8
/// surrounding voxels that hold one (weights renormalised, as readToonFields averages only the
/// cells that hold a velocity), or 0. Throws std::runtime_error naming the path when a grid is
/// missing, not axis-aligned, or has voxels outside `grid`'s box (more than half a cell out).
ToonFields resampleToonFields(const std::string& path, const GridFrame& grid);

/// The two volume frames read last, so that advancing frame by frame (f -> f+1, then f+1 -> f+2)
/// reads every file once. A file is read again when its size or modification time changed.
class ToonVolumeCache {
 public:
  /// resample: read with resampleToonFields (a traced Mantaflow bake) instead of readToonFields.
  explicit ToonVolumeCache(const GridFrame& grid, bool resample = false)
      : mGrid(grid), mResample(resample) {
    validateToonGrid(grid);
  }
  /// readToonFields(path, grid) (or resampleToonFields), or the cached copy. The reference stays valid until the second
  /// call after this one (the least recently used frame is replaced).
  const ToonFields& fields(const std::string& path);

 private:
  struct Entry {
    std::string path;
    std::uintmax_t size = 0;
    std::filesystem::file_time_type time;
    ToonFields fields;
  };
  GridFrame mGrid;
  bool mResample = false;
  Entry mEntries[2];
  int mRecent = 1;  ///< entry used last; the other is replaced on a miss
};

}  // namespace plume
