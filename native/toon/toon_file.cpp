/// \file toon_file.cpp
/// Toon particle cache. Layout (little-endian):
///   "PLUMETOON" | u32 version = 1 | i64 frame | u64 next id | u64 count N
///   | u64 ids[N] | f32 positions[3N] | f32 velocities[3N] | f32 density[N] | f32 temperature[N]
///   | f32 size[N] | f32 target size[N] | f32 color[N] | i32 age[N]
///   | u64 FNV-1a 64 of every byte before it.
/// Reading checks the header, then that N particles fit in the file, then the exact size, then
/// the checksum, and only then allocates and parses the arrays, which must then pass
/// ToonParticleState::validate.

#include "toon/toon_file.h"

#include "io/byte_buffer.h"

#include <cstdio>
#include <stdexcept>

namespace plume {
namespace {

constexpr char kMagic[9] = {'P', 'L', 'U', 'M', 'E', 'T', 'O', 'O', 'N'};
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderSize = sizeof(kMagic) + 4 + 8 + 8 + 8;
constexpr std::size_t kChecksumSize = 8;
/// id, position, velocity, five floats, age.
constexpr std::size_t kPerParticle = 8 + 12 + 12 + 5 * 4 + 4;
constexpr char kKind[] = "toon file";

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(std::string(kKind) + " '" + path + "' " + what);
}

void writeVec3(ByteWriter& w, const std::vector<glm::vec3>& v) {
  static_assert(sizeof(glm::vec3) == 12, "glm::vec3 must be three packed floats");
  w.floats(reinterpret_cast<const float*>(v.data()), 3 * v.size());
}

void readVec3(ByteReader& r, std::vector<glm::vec3>& v, std::size_t n) {
  v.resize(n);
  r.floats(reinterpret_cast<float*>(v.data()), 3 * n);
}

void readFloats(ByteReader& r, std::vector<float>& v, std::size_t n) {
  v.resize(n);
  r.floats(v.data(), n);
}

}  // namespace

std::string toonFileName(int frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "toon_%04d.bin", frame);
  return name;
}

void writeToonFile(const std::string& path, const ToonParticleState& s) {
  s.validate();
  const std::size_t n = s.count();
  ByteWriter w;
  w.reserve(kHeaderSize + kPerParticle * n + kChecksumSize);
  // Byte by byte: GCC 12 sees a bogus overflow in bytes() inlined here (-Wstringop-overflow).
  for (char c : kMagic) w.integer<std::uint8_t>(std::uint8_t(c));
  w.integer<std::uint32_t>(kVersion);
  w.integer<std::int64_t>(s.frame);
  w.integer<std::uint64_t>(s.nextId);
  w.integer<std::uint64_t>(n);
  for (std::uint64_t id : s.ids) w.integer<std::uint64_t>(id);
  writeVec3(w, s.positions);
  writeVec3(w, s.velocities);
  for (const std::vector<float>* a : {&s.density, &s.temperature, &s.size, &s.targetSize, &s.color})
    w.floats(a->data(), n);
  for (std::int32_t a : s.age) w.integer<std::int32_t>(a);
  w.checksum();
  writeFileAtomic(path, w.buffer(), kKind);
}

ToonParticleState readToonFile(const std::string& path) {
  const std::vector<unsigned char> buf =
      readFileChecked(path, kHeaderSize + kChecksumSize, std::size_t(1) << 36, kKind);
  ByteReader r(buf.data(), buf.size(), kKind, path);
  r.header(kMagic, sizeof(kMagic), kVersion);
  ToonParticleState s;
  s.frame = r.integer<std::int64_t>();
  s.nextId = r.integer<std::uint64_t>();
  const std::uint64_t count = r.integer<std::uint64_t>();
  // The arrays must fit before they are allocated.
  if (count > buf.size() / kPerParticle)
    fail(path, "is truncated or corrupt: " + std::to_string(count) +
                   " particles do not fit in " + std::to_string(buf.size()) + " bytes");
  const std::uint64_t expected = kHeaderSize + kPerParticle * count + kChecksumSize;
  if (expected != buf.size())
    fail(path, "has " + std::to_string(buf.size()) + " bytes; its header announces " +
                   std::to_string(expected) + " (truncated or corrupt)");
  if (!r.checksumMatches()) fail(path, "is corrupt (checksum mismatch)");
  const std::size_t n = std::size_t(count);
  s.ids.resize(n);
  for (std::uint64_t& id : s.ids) id = r.integer<std::uint64_t>();
  readVec3(r, s.positions, n);
  readVec3(r, s.velocities, n);
  for (std::vector<float>* a : {&s.density, &s.temperature, &s.size, &s.targetSize, &s.color})
    readFloats(r, *a, n);
  s.age.resize(n);
  for (std::int32_t& a : s.age) a = r.integer<std::int32_t>();
  if (r.remaining() != kChecksumSize) fail(path, "is corrupt (unexpected trailing bytes)");
  try {
    s.validate();
  } catch (const std::invalid_argument& e) {
    fail(path, std::string("is corrupt: ") + e.what());
  }
  return s;
}

}  // namespace plume
