#pragma once
/// \file vdb_guard.h
/// VDB files are checked byte by byte before OpenVDB parses any of them (a damaged or
/// half-copied file must give an error, never crash, stall or exhaust memory).
///
/// Why a check and not a patched OpenVDB or a forked reader: OpenVDB 10.0.1 (Debian's) trusts
/// the size fields of a file. It allocates string and metadata lengths as read, loops over tile
/// and child counts past the end of a short file, reads an uncompressed chunk into a leaf buffer
/// before comparing its length (a heap overflow written with the file's bytes) and hands Blosc a
/// buffer of the length the file claims. Plume reads only float and vec3s 5-4-3 trees, whose
/// format is small, so the whole file is read into memory once, every field OpenVDB will read is
/// checked against the bytes that follow and against the buffer it will fill, and OpenVDB then
/// parses a minimal copy of the checked bytes (io::Stream, never delayed loading, no
/// delayed-load metadata, only plain metadata types and linear transforms). The file is read
/// once, so a file rewritten during the read cannot slip past the check. A forked child would
/// catch faults the check misses but not stalls or memory use, costs a fork of Blender per frame
/// and is unavailable on Windows.

#include <openvdb/openvdb.h>

#include <string>
#include <vector>

namespace plume {

/// Largest VDB file read (bytes): the file is held in memory while it is read.
constexpr std::uint64_t kMaxVdbFileBytes = std::uint64_t(8) << 30;

/// A VDB file read whole and checked before OpenVDB sees it. Errors are std::runtime_error
/// messages without the path (the caller names the file), raw bytes escaped to UTF-8.
class CheckedVdbFile {
 public:
  /// Reads `path` and checks its header and grid descriptors (file versions 222-224, written by
  /// io::File: OpenVDB 3 and later).
  explicit CheckedVdbFile(const std::string& path);

  /// Grid names as io::File lists them: sorted, a repeated name as name[1], name[2], ...;
  /// bytes that are not UTF-8 escaped as \xNN (readGrid() finds the grid by that name too).
  std::vector<std::string> gridNames() const;

  /// Grid `name` (a name from gridNames()), or nullptr when there is none. Its tree must be a
  /// float or vec3s 5-4-3 tree (full or half precision); every byte of it is checked, then
  /// OpenVDB reads the checked copy.
  openvdb::GridBase::Ptr readGrid(const std::string& name) const;

  struct Descriptor {
    std::string uniqueName;  ///< as stored: name, or name + "\x1e" + index for a repeat
    std::string type;        ///< tree type without the "_HalfFloat" suffix
    bool half = false;
    std::size_t gridPos = 0, endPos = 0;
  };

 private:
  const Descriptor* find(const std::string& name) const;

  std::vector<unsigned char> mBytes;
  std::uint32_t mFileVersion = 0;
  std::uint32_t mLibraryMajor = 0, mLibraryMinor = 0;
  std::vector<Descriptor> mGrids;
};

}  // namespace plume
