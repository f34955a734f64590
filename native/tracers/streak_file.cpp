/// \file streak_file.cpp
/// Streak cache. Layout (little-endian):
///   "PLUMESTRK" | u32 version = 1 | u32 source count S | u32 counts[S] (particles per source)
///   | f32 positions[3 M] (x, y, z per particle, sources concatenated, birth order)
///   | f32 density[M] | i32 groups[S] | u8 outside[M] | u64 FNV-1a 64 of every byte before it,
/// with M = Σ counts. Reading checks the header, then that the counts fit in the file, then the
/// exact size, then the checksum, and only then allocates and parses the arrays, whose values
/// must be finite.

#include "tracers/streak_file.h"

#include "io/byte_buffer.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace plume {
namespace {

constexpr char kMagic[9] = {'P', 'L', 'U', 'M', 'E', 'S', 'T', 'R', 'K'};
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderSize = sizeof(kMagic) + 4 + 4;
constexpr std::size_t kChecksumSize = 8;
/// Bytes per source (count + group) and per particle (position, density, outside flag).
constexpr std::size_t kPerSource = 4 + 4;
constexpr std::size_t kPerParticle = 12 + 4 + 1;
constexpr char kKind[] = "streak file";

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(std::string(kKind) + " '" + path + "' " + what);
}

}  // namespace

std::string streakFileName(int frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "streaks_%04d.bin", frame);
  return name;
}

void writeStreakFile(const std::string& path, const StreakFrame& frame) {
  frame.validate();
  const std::size_t sources = frame.counts.size(), particles = frame.positions.size();
  if (sources > std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("streak frame: too many sources for the file format");
  ByteWriter w;
  w.reserve(kHeaderSize + kPerSource * sources + kPerParticle * particles + kChecksumSize);
  w.bytes(kMagic, sizeof(kMagic));
  w.integer<std::uint32_t>(kVersion);
  w.integer<std::uint32_t>(std::uint32_t(sources));
  for (int c : frame.counts) w.integer<std::uint32_t>(std::uint32_t(c));
  static_assert(sizeof(glm::vec3) == 12, "glm::vec3 must be three packed floats");
  w.floats(reinterpret_cast<const float*>(frame.positions.data()), 3 * particles);
  w.floats(frame.density.data(), particles);
  for (int g : frame.groups) w.integer<std::int32_t>(g);
  w.bytes(frame.outside.data(), particles);
  w.checksum();
  writeFileAtomic(path, w.buffer(), kKind);
}

StreakFrame readStreakFile(const std::string& path) {
  const std::vector<unsigned char> buf =
      readFileChecked(path, kHeaderSize + kChecksumSize, std::size_t(1) << 36, kKind);
  ByteReader r(buf.data(), buf.size(), kKind, path);
  r.header(kMagic, sizeof(kMagic), kVersion);
  const std::uint64_t sources = r.integer<std::uint32_t>();
  // The per-source arrays must fit before they are allocated.
  if (sources * kPerSource > buf.size() - kHeaderSize - kChecksumSize)
    fail(path, "is truncated or corrupt: " + std::to_string(sources) +
                   " sources do not fit in " + std::to_string(buf.size()) + " bytes");
  StreakFrame f;
  f.counts.resize(std::size_t(sources));
  std::uint64_t particles = 0;
  for (std::size_t s = 0; s < sources; ++s) {
    const std::uint32_t c = r.integer<std::uint32_t>();
    if (c > std::uint32_t(std::numeric_limits<int>::max()))
      fail(path, "is corrupt: source " + std::to_string(s) + " has " + std::to_string(c) +
                     " particles");
    f.counts[s] = int(c);
    particles += c;  // ≤ 2^32 × 2^31, no overflow in 64 bits
  }
  if (particles > buf.size() / kPerParticle)
    fail(path, "is truncated or corrupt: " + std::to_string(particles) +
                   " particles do not fit in " + std::to_string(buf.size()) + " bytes");
  const std::uint64_t expected =
      kHeaderSize + kPerSource * sources + kPerParticle * particles + kChecksumSize;
  if (expected != buf.size())
    fail(path, "has " + std::to_string(buf.size()) + " bytes; its header announces " +
                   std::to_string(expected) + " (truncated or corrupt)");
  if (!r.checksumMatches()) fail(path, "is corrupt (checksum mismatch)");
  const std::size_t m = std::size_t(particles);
  f.positions.resize(m);
  r.floats(reinterpret_cast<float*>(f.positions.data()), 3 * m);
  f.density.resize(m);
  r.floats(f.density.data(), m);
  f.groups.resize(std::size_t(sources));
  for (int& g : f.groups) g = r.integer<std::int32_t>();
  f.outside.resize(m);
  r.bytes(f.outside.data(), m);
  if (r.remaining() != kChecksumSize) fail(path, "is corrupt (unexpected trailing bytes)");
  for (std::uint8_t o : f.outside)
    if (o > 1) fail(path, "is corrupt (bad outside flag)");
  // A checksum only proves the bytes are the ones written: a NaN or infinity (a hand-made or
  // damaged file) would become a grid cell index in streak/candidate_pairs.cpp.
  for (std::size_t i = 0; i < m; ++i) {
    const glm::vec3& x = f.positions[i];
    if (!std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(x.z) ||
        !std::isfinite(f.density[i]))
      fail(path, "is corrupt: particle " + std::to_string(i) +
                     " has a non-finite position or density");
  }
  return f;
}

}  // namespace plume
