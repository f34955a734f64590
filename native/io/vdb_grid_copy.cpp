/// \file vdb_grid_copy.cpp
/// Grid metadata and transform checked and copied into a one-grid VDB stream.

#include "io/vdb_grid_copy.h"

#include <openvdb/openvdb.h>

#include <cmath>
#include <cstring>
#include <map>
#include <stdexcept>

#include "io/byte_buffer.h"
#include "io/utf8_text.h"
#include "io/vdb_tree_check.h"

namespace plume {
namespace {

[[noreturn]] void bad(const std::string& what) { throw std::runtime_error(what); }

void putString(ByteWriter& w, const std::string& s) {
  w.integer<std::uint32_t>(std::uint32_t(s.size()));
  w.bytes(s.data(), s.size());
}

/// Value sizes of the metadata types copied (openvdb/Metadata.h typeName()s).
const std::map<std::string, std::size_t>& plainMetadata() {
  static const std::map<std::string, std::size_t> sizes = {
      {"bool", 1},   {"int32", 4},  {"int64", 8},  {"float", 4},  {"double", 8},
      {"vec2i", 8},  {"vec2s", 8},  {"vec2d", 16}, {"vec3i", 12}, {"vec3s", 12},
      {"vec3d", 24}, {"vec4i", 16}, {"vec4s", 16}, {"vec4d", 32}, {"mat4s", 64},
      {"mat4d", 128}};
  return sizes;
}

/// MetaMap::readMeta: count, then name, type name, byte count and value per entry. OpenVDB
/// takes the half-float flag of the tree from the metadata `is_saved_as_half_float` (any type,
/// read after the descriptor's flag), so the file's entry is replaced by `half`, the descriptor's
/// flag the tree is checked with.
void copyMetadata(VdbCursor& c, ByteWriter& w, bool half) {
  const std::uint32_t count = c.pod<std::uint32_t>("metadata count");
  c.need(std::uint64_t(count) * 12, "metadata entries");
  ByteWriter kept;
  std::uint32_t keptCount = 0;
  for (std::uint32_t m = 0; m < count; ++m) {
    const std::string name = c.string("metadata name");
    const std::string type = c.string("metadata type");
    const std::uint32_t size = c.pod<std::uint32_t>("metadata size");
    const unsigned char* value = c.at(c.skip(size, "metadata value"));
    const auto plain = plainMetadata().find(type);
    if (type != "string" && plain == plainMetadata().end()) continue;  // not read by Plume
    if (name == openvdb::GridBase::META_SAVE_HALF_FLOAT) continue;
    if (plain != plainMetadata().end() && plain->second != size)
      bad("metadata '" + name + "' of type " + type + " holds " + std::to_string(size) +
          " bytes; the type has " + std::to_string(plain->second));
    if (type == "bool" && value[0] > 1) bad("metadata '" + name + "' is a bool other than 0/1");
    putString(kept, name);
    putString(kept, type);
    kept.integer<std::uint32_t>(size);
    kept.bytes(value, size);
    ++keptCount;
  }
  putString(kept, openvdb::GridBase::META_SAVE_HALF_FLOAT);
  putString(kept, "bool");
  kept.integer<std::uint32_t>(1);
  kept.integer<std::uint8_t>(half ? 1 : 0);
  w.integer<std::uint32_t>(keptCount + 1);
  w.bytes(kept.buffer().data(), kept.buffer().size());
}

/// Transform::read: map type name, then the map's doubles (openvdb/math/Maps.h read()).
void copyTransform(VdbCursor& c, ByteWriter& w) {
  static const std::map<std::string, std::size_t> doubles = {
      {"UniformScaleMap", 15}, {"ScaleMap", 15},  {"UniformScaleTranslateMap", 18},
      {"ScaleTranslateMap", 18}, {"TranslationMap", 3}, {"AffineMap", 16}, {"UnitaryMap", 16}};
  const std::string type = c.string("transform type");
  const auto it = doubles.find(type);
  if (it == doubles.end())
    bad("transform of type '" + type + "'; Plume reads linear transforms (scale, translation, "
        "affine)");
  const unsigned char* p = c.at(c.skip(it->second * 8, "transform"));
  for (std::size_t k = 0; k < it->second; ++k) {
    double v;
    std::memcpy(&v, p + 8 * k, 8);
    if (!std::isfinite(v)) bad("transform entries that are not finite numbers");
  }
  putString(w, type);
  w.bytes(p, it->second * 8);
}

}  // namespace

std::string checkedGridStream(const VdbGridSource& s) {
  VdbCursor c(s.bytes, s.gridPos, s.endPos);
  const std::uint32_t compression = c.pod<std::uint32_t>("compression flags");
  if (compression & ~std::uint32_t(0x7))
    bad("compression flags " + std::to_string(compression) + " (known: zip 1, mask 2, blosc 4)");
  ByteWriter w;
  // Header (Archive::writeHeader of a non-seekable stream), no file metadata, one grid.
  w.integer<std::int64_t>(0x56444220);  // OPENVDB_MAGIC
  w.integer<std::uint32_t>(s.fileVersion);
  w.integer<std::uint32_t>(s.libraryMajor);
  w.integer<std::uint32_t>(s.libraryMinor);
  w.integer<std::uint8_t>(0);  // no grid offsets
  const std::string uuid = "00000000-0000-0000-0000-000000000000";
  w.bytes(uuid.data(), uuid.size());
  w.integer<std::uint32_t>(0);  // file metadata count
  w.integer<std::int32_t>(1);   // grid count
  putString(w, s.name);
  putString(w, s.type + (s.half ? "_HalfFloat" : ""));
  putString(w, "");  // not an instance
  for (int k = 0; k < 3; ++k) w.integer<std::int64_t>(0);  // offsets, unused by io::Stream
  w.integer<std::uint32_t>(compression);
  copyMetadata(c, w, s.half);
  copyTransform(c, w);
  VdbTreeFormat f;
  f.valueBytes = s.type == "Tree_float_5_4_3" ? 4 : 12;
  f.floatCount = f.valueBytes / 4;
  f.half = s.half;
  f.compression = compression;
  const std::size_t tree = c.position();
  checkVdbTree(c, f);
  w.bytes(s.bytes + tree, c.position() - tree);
  const auto& b = w.buffer();
  return std::string(reinterpret_cast<const char*>(b.data()), b.size());
}

}  // namespace plume
