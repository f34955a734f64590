/// \file vdb_tree_check.cpp
/// The byte-level check of a 5-4-3 VDB tree, mirroring OpenVDB 10.0.1's RootNode, InternalNode
/// and LeafNode readTopology/readBuffers and io::readCompressedValues.

#include "io/vdb_tree_check.h"

#include <bitset>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

// io::COMPRESS_* (openvdb/io/Compression.h).
constexpr std::uint32_t kZip = 0x1, kActiveMask = 0x2, kBlosc = 0x4;
constexpr std::size_t kBloscHeader = 16;  // BLOSC_MIN_HEADER_LENGTH
constexpr std::int32_t kRootChildDim = 4096;  // 32 * 16 * 8 voxels

[[noreturn]] void bad(const std::string& what) { throw std::runtime_error(what); }

std::size_t countOn(const unsigned char* mask, std::size_t bytes) {
  std::size_t n = 0;
  for (std::size_t b = 0; b < bytes; ++b) n += std::bitset<8>(mask[b]).count();
  return n;
}

std::uint32_t le32(const unsigned char* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
         std::uint32_t(p[3]) << 24;
}

/// One chunk of `bytes` bytes as io::readData reads it.
void checkChunk(VdbCursor& c, const VdbTreeFormat& f, std::size_t bytes) {
  if (!(f.compression & (kBlosc | kZip))) {
    c.skip(bytes, "uncompressed values");
    return;
  }
  const std::int64_t n = c.pod<std::int64_t>("chunk size");
  if (n <= 0) {
    // OpenVDB reads -n bytes into the `bytes`-byte buffer, then compares.
    if (n == std::numeric_limits<std::int64_t>::min() || std::uint64_t(-n) != bytes)
      bad("an uncompressed chunk of " + std::to_string(std::uint64_t(0) - std::uint64_t(n)) +
          " bytes where the node holds " + std::to_string(bytes));
    c.skip(bytes, "uncompressed chunk");
    return;
  }
  c.need(std::size_t(n), "compressed chunk");
  if (f.compression & kBlosc) {
    // OpenVDB hands blosc a buffer of n bytes with no length: blosc trusts the header's cbytes.
    if (std::uint64_t(n) < kBloscHeader)
      bad("a Blosc chunk of " + std::to_string(n) + " bytes, shorter than its header");
    const unsigned char* h = c.at(c.position());
    const std::uint32_t nbytes = le32(h + 4), cbytes = le32(h + 12);
    if (cbytes != std::uint64_t(n))
      bad("a Blosc chunk of " + std::to_string(n) + " bytes whose header claims " +
          std::to_string(cbytes));
    if (nbytes != bytes)
      bad("a Blosc chunk that decompresses to " + std::to_string(nbytes) +
          " bytes where the node holds " + std::to_string(bytes));
  }
  c.skip(std::size_t(n), "compressed chunk");
}

/// Checks that `count` values of the tree's type at `p` are finite numbers.
void checkFinite(const unsigned char* p, std::size_t count, const VdbTreeFormat& f,
                 const char* what) {
  for (std::size_t k = 0; k < count * f.floatCount; ++k) {
    float v;
    std::memcpy(&v, p + 4 * k, 4);
    if (!std::isfinite(v)) bad(std::string(what) + " is not a finite number");
  }
}

/// io::readCompressedValues of `destCount` values selected by the value mask at `mask`.
void checkValues(VdbCursor& c, const VdbTreeFormat& f, const unsigned char* mask,
                 std::size_t maskBytes, std::size_t destCount) {
  const auto meta = c.pod<std::int8_t>("value compression flag");
  if (meta < 0 || meta > 6) bad("value compression flag " + std::to_string(meta) + " (0-6)");
  if (meta == 2 || meta == 4 || meta == 5) c.skip(f.valueBytes, "inactive value");
  if (meta == 5) c.skip(f.valueBytes, "second inactive value");
  if (meta >= 3 && meta <= 5) c.skip(maskBytes, "selection mask");
  std::size_t count = destCount;
  if ((f.compression & kActiveMask) && meta != 6) count = countOn(mask, maskBytes);
  if (f.half && count == 0) return;  // HalfReader reads nothing for no values
  checkChunk(c, f, count * (f.half ? f.valueBytes / 2 : f.valueBytes));
}

/// InternalNode<ChildT, log2> topology: child mask, value mask, tile values, children.
void checkInternal(VdbCursor& c, const VdbTreeFormat& f, int log2, std::uint64_t& leaves) {
  const std::size_t maskBytes = (std::size_t(1) << (3 * log2)) / 8;
  const std::size_t childMask = c.skip(maskBytes, "child mask");
  const std::size_t valueMask = c.skip(maskBytes, "value mask");
  for (std::size_t b = 0; b < maskBytes; ++b)
    if (*c.at(childMask + b) & *c.at(valueMask + b))
      bad("an internal node whose child and value masks overlap");
  checkValues(c, f, c.at(valueMask), maskBytes, maskBytes * 8);
  const std::size_t children = countOn(c.at(childMask), maskBytes);
  for (std::size_t k = 0; k < children; ++k) {
    if (log2 == 4) {
      c.skip(64, "leaf value mask");
      if (++leaves > f.maxLeaves)
        bad("more than " + std::to_string(f.maxLeaves) + " leaf nodes (2^30 voxels)");
    } else {
      checkInternal(c, f, 4, leaves);
    }
  }
}

bool coordLess(const std::int32_t* a, const std::int32_t* b) {
  for (int k = 0; k < 3; ++k)
    if (a[k] != b[k]) return a[k] < b[k];
  return false;
}

void readOrigin(VdbCursor& c, const VdbTreeFormat& f, std::int32_t* v, const char* what) {
  for (int k = 0; k < 3; ++k) {
    v[k] = c.pod<std::int32_t>(what);
    if (v[k] % kRootChildDim != 0 || v[k] < -f.coordLimit ||
        v[k] > f.coordLimit - kRootChildDim)
      bad(std::string(what) + " (" + std::to_string(v[k]) +
          ") is not a multiple of 4096 in [-2^24, 2^24)");
  }
}

}  // namespace

void checkVdbTree(VdbCursor& c, const VdbTreeFormat& f) {
  if (c.pod<std::int32_t>("buffer count") != 1) bad("a tree buffer count other than 1");
  checkFinite(c.at(c.skip(f.valueBytes, "background")), 1, f, "the background value");
  const std::uint32_t tiles = c.pod<std::uint32_t>("tile count");
  const std::uint32_t children = c.pod<std::uint32_t>("child count");
  c.need(std::uint64_t(tiles) * (12 + f.valueBytes + 1), "root tiles");
  std::int32_t v[3];
  for (std::uint32_t t = 0; t < tiles; ++t) {
    readOrigin(c, f, v, "a root tile origin");
    c.skip(f.valueBytes, "tile value");
    if (c.pod<std::uint8_t>("tile state") > 1) bad("a tile state other than 0 or 1");
  }
  std::int32_t last[3] = {0, 0, 0};
  std::uint64_t leaves = 0;
  for (std::uint32_t n = 0; n < children; ++n) {
    readOrigin(c, f, v, "a root child origin");
    if (n > 0 && !coordLess(last, v)) bad("root children out of order or repeated");
    std::memcpy(last, v, sizeof v);
    checkInternal(c, f, 5, leaves);
  }
  // Leaf buffers, in the order of the topology: value mask, then the values it selects.
  for (std::uint64_t l = 0; l < leaves; ++l) {
    const std::size_t mask = c.skip(64, "leaf value mask");
    checkValues(c, f, c.at(mask), 64, 512);
  }
}

}  // namespace plume
