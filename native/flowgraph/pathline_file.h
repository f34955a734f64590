#pragma once
/// \file pathline_file.h
/// The pathline file of one fire bake ([Graph Fire Synthesis] §4.2: "compact storage", one
/// file per state, `pathlines.bin` in the bake folder), written group by group while the bake
/// runs and read one node at a time.
///
/// Layout (version 1, little endian):
///   header  (80 bytes): magic "PLUMEPTH", u32 version, u32 flags (bit 0: float16 samples),
///           i32 particles |Ω|, i32 samples L, f32 Δt_n, i32 resolution[3], f32 cell size,
///           f32 origin[3], i32 nodes per frame, u32 node count, u64 table offset,
///           u64 checksum of the 72 bytes before it
///   nodes   one block per node k = 0, 1, ... (the group seeded at node step k):
///           i32 step, u32 0, f32 start[|Ω|][3], then velocity [|Ω|][L][3], density [|Ω|][L],
///           temperature [|Ω|][L] as f32, or as IEEE half (u16) with the float16 flag
///   table   per node: u64 offset, u64 checksum of its block; then u64 checksum of the table
/// Bytes per node: 8 + 12|Ω| + 5 |Ω| L × (4, or 2 with float16) (e.g. 3.1 MB, or 1.6 MB in
/// half precision, for |Ω| = 3,200 and L = 48).
///
/// Crash safety: the writer builds "<path>.partial" whose header says "incomplete" (node count
/// 0xffffffff, table offset 0) until finish() has written the table, rewritten the header and
/// renamed it to <path>. The writer removes an older <path> when it starts (its pathlines are
/// being replaced), so a killed bake leaves no <path> at all, only the ".partial" file, whose
/// header still reads "incomplete": never a file that reads as complete with missing nodes.

#include "flowgraph/pathline_group.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace plume {

/// What the header of a pathline file says about its bake and its groups.
struct PathlineFileInfo {
  PathlineLayout layout;         ///< |Ω|, L and Δt_n shared by every node
  glm::ivec3 resolution{0};      ///< the bake's grid, cells per axis
  float cellSize = 0.f;          ///< Δx of the bake, metres
  glm::vec3 origin{0.f};         ///< world position of the domain's minimum corner
  int nodesPerFrame = 1;         ///< node steps per frame (Δt_n = frame_dt / nodes_per_frame)
  bool float16 = false;          ///< samples stored in half precision (start positions stay f32)
  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
  /// Size in bytes of one node block.
  std::size_t blockBytes() const;
};

/// Largest accepted |Ω| × L per group (a file is never trusted beyond it): 2^28 samples.
constexpr std::uint64_t kMaxPathlineSamples = std::uint64_t(1) << 28;
/// Largest accepted node count of one file.
constexpr std::uint32_t kMaxPathlineNodes = 10000000;

/// Writes a pathline file incrementally: append() each group as it completes, then finish().
class PathlineFileWriter {
 public:
  /// Starts "<path>.partial" (truncating a stale one) with an "incomplete" header and removes
  /// an older <path>. Throws std::invalid_argument for bad info, std::runtime_error naming the
  /// file when it cannot be written.
  PathlineFileWriter(const std::string& path, const PathlineFileInfo& info);
  /// Leaves "<path>.partial" behind unless finish() or discard() ran, exactly as a killed bake
  /// would: it never reads as complete.
  ~PathlineFileWriter();
  PathlineFileWriter(const PathlineFileWriter&) = delete;
  PathlineFileWriter& operator=(const PathlineFileWriter&) = delete;

  /// Appends node nodeCount(): `group` must have the file's layout, step == nodeCount() and
  /// consistent array sizes (std::invalid_argument otherwise). Values beyond the half range are
  /// clamped to ±65504 in float16 files. std::runtime_error naming the file on a write error.
  void append(const PathlineGroup& group);
  /// Writes the node table, marks the header complete, flushes and renames the file to path().
  void finish();
  /// Closes and removes "<path>.partial" (a cancelled bake). No effect after finish().
  void discard();

  int nodeCount() const { return int(mTable.size()); }
  const PathlineFileInfo& info() const { return mInfo; }
  const std::string& path() const { return mPath; }
  std::string partialPath() const { return mPath + ".partial"; }
  bool finished() const { return mFinished; }

 private:
  struct Entry {
    std::uint64_t offset, checksum;
  };
  void fail(const std::string& what);

  std::string mPath;
  PathlineFileInfo mInfo;
  std::ofstream mOut;
  std::vector<Entry> mTable;
  std::vector<unsigned char> mBlock;  ///< encoding buffer, reused by every append()
  std::uint64_t mOffset = 0;
  bool mFinished = false, mClosed = false;
};

/// A complete pathline file opened for lazy reading: open() reads the header and the node table
/// only; readGroup() reads one node. Thread-safe for concurrent readGroup() calls.
class PathlineFile {
 public:
  /// Reads and checks the header and table (sizes checked against the file size, never trusted).
  /// Throws std::runtime_error naming the file when it is missing, incomplete (a bake that did
  /// not finish), truncated, corrupt (checksum) or of another version.
  static PathlineFile open(const std::string& path);

  const std::string& path() const { return mPath; }
  const PathlineFileInfo& info() const { return mInfo; }
  const PathlineLayout& layout() const { return mInfo.layout; }
  int nodeCount() const { return int(mOffsets.size()); }
  /// Bytes of one node block on disk.
  std::size_t bytesPerNode() const { return mInfo.blockBytes(); }

  /// Node k (0 <= k < nodeCount()): its block is read, its checksum verified and its samples
  /// decoded into `out` (buffers reused). `state` is copied into out.state. Throws
  /// std::out_of_range for a bad k, std::runtime_error naming the file when the block is
  /// unreadable or corrupt (checksum, step, or a non-finite value).
  void readGroup(int k, PathlineGroup& out, int state = 0) const;
  PathlineGroup readGroup(int k, int state = 0) const;

 private:
  std::string mPath;
  PathlineFileInfo mInfo;
  std::vector<std::uint64_t> mOffsets, mChecksums;
};

/// Checksum of the pathline file's blocks and table: FNV-1a 64 over 8-byte little-endian words
/// in four interleaved lanes (about 10x the speed of the bytewise FNV-1a of byte_buffer.h, which
/// matters for megabyte blocks read at every synthesis step), the tail bytewise.
std::uint64_t pathlineChecksum(const unsigned char* data, std::size_t size);

/// IEEE 754 binary16 conversions used by float16 files (OpenVDB's half: round to nearest even;
/// values beyond ±65504 are clamped to it, NaN becomes 0).
std::uint16_t floatToHalf(float value);
float halfToFloat(std::uint16_t bits);

}  // namespace plume
