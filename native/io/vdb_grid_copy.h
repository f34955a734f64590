#pragma once
/// \file vdb_grid_copy.h
/// The minimal VDB stream OpenVDB reads after the check (vdb_guard.h): one grid, its plain
/// metadata, its linear transform and its checked tree, copied from a file's bytes.

#include <cstdint>
#include <string>

#include "io/vdb_cursor.h"

namespace plume {

/// Where the grid lies in the file and how the file stores it.
struct VdbGridSource {
  const unsigned char* bytes = nullptr;
  std::size_t gridPos = 0, endPos = 0;  ///< the grid's bytes, from the file's descriptor
  std::uint32_t fileVersion = 224;       ///< 222-224
  std::uint32_t libraryMajor = 0, libraryMinor = 0;
  std::string name;
  std::string type;  ///< "Tree_float_5_4_3" or "Tree_vec3s_5_4_3"
  bool half = false;
};

/// Checks the grid's compression flags, metadata, transform and tree and returns a VDB stream
/// (io::Stream format) holding only that grid: metadata of the plain types (bool, int32, int64,
/// float, double, string, vec2/3/4 i/s/d, mat4s/d; others, delayed-load metadata included, are
/// dropped), the transform if it is linear with finite entries, and the tree bytes once
/// checkVdbTree() accepted them. Throws std::runtime_error naming the bad field.
std::string checkedGridStream(const VdbGridSource& source);

}  // namespace plume
