/// \file vdb_guard.cpp
/// A VDB file read whole, its header and grid descriptors checked, its grids handed to OpenVDB
/// only as checked copies (vdb_grid_copy.h).

#include "io/vdb_guard.h"

#include <openvdb/io/Stream.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <cctype>
#include <stdexcept>

#include "io/utf8_text.h"
#include "io/vdb_cursor.h"
#include "io/vdb_grid_copy.h"

namespace plume {
namespace {

[[noreturn]] void bad(const std::string& what) { throw std::runtime_error(cleanUtf8(what)); }

constexpr char kSeparator = '\x1e';  // GridDescriptor's suffix separator

/// GridDescriptor::nameAsString: "name\x1eN" as "name[N]".
std::string displayName(const std::string& unique) {
  const std::size_t sep = unique.find(kSeparator);
  if (sep == std::string::npos) return unique;
  return unique.substr(0, sep) + "[" + unique.substr(sep + 1) + "]";
}

std::string baseName(const std::string& unique) { return unique.substr(0, unique.find(kSeparator)); }

std::vector<unsigned char> readWhole(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) bad("cannot be opened");
  const std::streamoff size = in.tellg();
  if (size < 0) bad("cannot be opened");
  if (std::uint64_t(size) > kMaxVdbFileBytes)
    bad("is " + std::to_string(size) + " bytes; Plume reads VDB files up to " +
        std::to_string(kMaxVdbFileBytes) + " bytes");
  std::vector<unsigned char> bytes(static_cast<std::size_t>(size));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(bytes.data()), size);
  bytes.resize(static_cast<std::size_t>(in.gcount()));  // a file shrinking now reads as short
  return bytes;
}

/// Archive::readHeader for versions 222-224; the UUID is 36 hexadecimal digits and hyphens.
void checkHeader(VdbCursor& c, std::uint32_t& version, std::uint32_t& major,
                 std::uint32_t& minor) {
  if (c.remaining() < 8 || c.pod<std::int64_t>("magic number") != 0x56444220)
    bad("is not a VDB file (no VDB magic number)");
  version = c.pod<std::uint32_t>("file version");
  if (version < 222 || version > openvdb::OPENVDB_FILE_VERSION)
    bad("has VDB file version " + std::to_string(version) + "; Plume reads versions 222-" +
        std::to_string(openvdb::OPENVDB_FILE_VERSION) + " (OpenVDB 3.0 to 10)");
  major = c.pod<std::uint32_t>("library version");
  minor = c.pod<std::uint32_t>("library version");
  if (c.pod<std::uint8_t>("grid offsets flag") != 1)
    bad("is a VDB stream without grid offsets; Plume reads files written by io::File");
  const unsigned char* uuid = c.at(c.skip(36, "file UUID"));
  for (int k = 0; k < 36; ++k) {
    const bool hyphen = k == 8 || k == 13 || k == 18 || k == 23;
    if (hyphen ? uuid[k] != '-' : !std::isxdigit(uuid[k])) bad("has a damaged file UUID");
  }
}

/// MetaMap::readMeta, skipped: count, then name, type name, byte count and value per entry.
void skipMetadata(VdbCursor& c) {
  const std::uint32_t count = c.pod<std::uint32_t>("file metadata count");
  c.need(std::uint64_t(count) * 12, "file metadata");
  for (std::uint32_t m = 0; m < count; ++m) {
    c.string("file metadata name");
    c.string("file metadata type");
    c.skip(c.pod<std::uint32_t>("file metadata size"), "file metadata value");
  }
}

}  // namespace

CheckedVdbFile::CheckedVdbFile(const std::string& path) : mBytes(readWhole(path)) {
  try {
    VdbCursor c(mBytes.data(), 0, mBytes.size());
    checkHeader(c, mFileVersion, mLibraryMajor, mLibraryMinor);
    skipMetadata(c);
    const std::int32_t count = c.pod<std::int32_t>("grid count");
    if (count < 0 || std::uint64_t(count) * 36 > c.remaining())
      bad("claims " + std::to_string(count) + " grids in " + std::to_string(c.remaining()) +
          " bytes");
    for (std::int32_t g = 0; g < count; ++g) {
      Descriptor d;
      d.uniqueName = c.string("grid name");
      d.type = c.string("grid type");
      const std::string suffix = "_HalfFloat";
      if (d.type.size() > suffix.size() &&
          d.type.compare(d.type.size() - suffix.size(), suffix.size(), suffix) == 0) {
        d.half = true;
        d.type.resize(d.type.size() - suffix.size());
      }
      if (!c.string("instance parent").empty())
        bad("grid '" + displayName(d.uniqueName) + "' is an instance of another grid");
      const auto gridPos = c.pod<std::int64_t>("grid position");
      c.pod<std::int64_t>("grid block position");
      const auto endPos = c.pod<std::int64_t>("grid end position");
      if (gridPos != std::int64_t(c.position()) || endPos < gridPos ||
          std::uint64_t(endPos) > mBytes.size())
        bad("grid '" + displayName(d.uniqueName) + "' spans bytes " + std::to_string(gridPos) +
            " to " + std::to_string(endPos) + " of a " + std::to_string(mBytes.size()) +
            "-byte file (truncated or damaged)");
      d.gridPos = std::size_t(gridPos);
      d.endPos = std::size_t(endPos);
      c.skip(d.endPos - d.gridPos, "grid");
      mGrids.push_back(std::move(d));
    }
  } catch (const std::exception& e) {
    bad(e.what());
  }
}

std::vector<std::string> CheckedVdbFile::gridNames() const {
  std::vector<const Descriptor*> sorted;
  for (const Descriptor& d : mGrids) sorted.push_back(&d);
  std::stable_sort(sorted.begin(), sorted.end(), [](const Descriptor* a, const Descriptor* b) {
    return baseName(a->uniqueName) < baseName(b->uniqueName);
  });
  std::vector<std::string> names;
  for (const Descriptor* d : sorted) names.push_back(cleanUtf8(displayName(d->uniqueName)));
  return names;
}

const CheckedVdbFile::Descriptor* CheckedVdbFile::find(const std::string& name) const {
  for (const Descriptor& d : mGrids)
    if (d.uniqueName == name || displayName(d.uniqueName) == name ||
        cleanUtf8(displayName(d.uniqueName)) == name)
      return &d;
  return nullptr;
}

openvdb::GridBase::Ptr CheckedVdbFile::readGrid(const std::string& name) const {
  const Descriptor* d = find(name);
  if (!d) return nullptr;
  if (d->type != "Tree_float_5_4_3" && d->type != "Tree_vec3s_5_4_3")
    bad("grid '" + name + "' is of type " + d->type + "; Plume reads float and vec3s grids");
  VdbGridSource s;
  s.bytes = mBytes.data();
  s.gridPos = d->gridPos;
  s.endPos = d->endPos;
  s.fileVersion = mFileVersion;
  s.libraryMajor = mLibraryMajor;
  s.libraryMinor = mLibraryMinor;
  s.name = baseName(d->uniqueName);
  s.type = d->type;
  s.half = d->half;
  try {
    std::istringstream in(checkedGridStream(s), std::ios::binary);
    openvdb::io::Stream stream(in, /*delayLoad=*/false);
    const openvdb::GridPtrVecPtr grids = stream.getGrids();
    if (!grids || grids->size() != 1 || !(*grids)[0]) bad("OpenVDB read no grid");
    return (*grids)[0];
  } catch (const std::bad_alloc&) {
    bad("grid '" + name + "' does not fit in memory");
  } catch (const std::exception& e) {
    bad("grid '" + name + "': " + e.what());
  }
}

}  // namespace plume
