#pragma once
/// \file vdb_tree_check.h
/// Checks the bytes of a VDB tree (topology and leaf buffers) before OpenVDB reads them: every
/// size field against the bytes that follow and against the size OpenVDB 10.0.1 will decompress
/// into, where OpenVDB's own reader writes first and checks after (io/Compression.cc: an
/// uncompressed chunk is read into the leaf buffer before its length is compared, a Blosc chunk
/// is decompressed from a buffer of the length the file claims).

#include <cstdint>

#include "io/vdb_cursor.h"

namespace plume {

/// How a Tree_<T>_5_4_3 is stored (OpenVDB's standard float and vec3s trees).
struct VdbTreeFormat {
  std::size_t valueBytes = 4;   ///< sizeof(ValueType): 4 (float) or 12 (vec3s)
  std::size_t floatCount = 1;   ///< floats per value: 1 or 3
  bool half = false;            ///< leaf and tile values stored as 16-bit halves
  std::uint32_t compression = 0;  ///< io::COMPRESS_* flags of the grid
  /// Root-level node origins must lie in [-coordLimit, coordLimit - 4096] per axis, so that no
  /// voxel coordinate or box size computed from them overflows an int.
  std::int32_t coordLimit = 1 << 24;
  std::uint64_t maxLeaves = 1 << 21;  ///< 2^30 voxels: the largest dense box Plume reads
};

/// Checks the tree at `c` as Tree::readTopology then Tree::readBuffers will read it from a
/// non-seekable stream of file version >= 222, and moves `c` past it. Throws std::runtime_error
/// describing the first bad field (sizes, masks, node origins out of range or out of order,
/// Blosc headers that do not match the chunk, values that are not finite where they are used).
void checkVdbTree(VdbCursor& c, const VdbTreeFormat& format);

}  // namespace plume
