/// \file tracer_state_file.cpp
/// Tracer checkpoint. Layout (little-endian):
///   "PLUMETRACE" | u32 version = 2 | i32 frame
///   | i32 emission period | u32 interpolation | i32 nx, ny, nz | f32 cell size | f32 origin[3]
///   | u8 boundaries[6] | i64 steps | i32 emissions | u64 source count S | u64 particle count M
///   | i64 step of the youngest emission | u8 emitting (0/1)   (version 2 only: Figure 10's pause)
///   | per source: f32 position[3], i32 group, f32 velocity[3]
///   | f32 positions[3 M] | f32 density[M] | u8 outside[M] | f32 exit velocities[3 M]
///   | u64 FNV-1a 64 of every byte before it,
/// particles emission-major as in StreakTracerState. Reading checks the magic and version, the
/// checksum, the settings against the tracer's, then the exact size the counts announce; only
/// then are the arrays allocated and parsed, and the tracer is touched only once all is read.
/// Version 1 files (written before emission could pause) are read as never paused.

#include "tracers/tracer_state_file.h"

#include "io/byte_buffer.h"

#include <array>
#include <stdexcept>
#include <utility>

namespace plume {
namespace {

constexpr char kMagic[10] = {'P', 'L', 'U', 'M', 'E', 'T', 'R', 'A', 'C', 'E'};
constexpr std::uint32_t kVersion = 2;
/// Oldest version read: version 1 lacks the pause fields (emission never paused then).
constexpr std::uint32_t kOldestVersion = 1;
constexpr std::size_t kHeaderSizeV1 = sizeof(kMagic) + 4 + 4 + 4 + 4 + 12 + 4 + 12 + 6 + 8 + 4 + 8 + 8;
/// Version 2 adds the step of the youngest emission (i64) and the emitting flag (u8).
constexpr std::size_t kHeaderSize = kHeaderSizeV1 + 8 + 1;
constexpr std::size_t kChecksumSize = 8;
/// Bytes per source (position, group, velocity) and per particle (position, density, outside
/// flag, exit velocity).
constexpr std::size_t kPerSource = 12 + 4 + 12;
constexpr std::size_t kPerParticle = 12 + 4 + 1 + 12;
/// Largest file read: far above any bake (2^36 bytes = 64 GiB), so a corrupt size cannot
/// allocate without bound.
constexpr std::size_t kMaxFileSize = std::size_t(1) << 36;
constexpr char kKind[] = "tracer state file";

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(std::string(kKind) + " '" + path + "' " + what);
}

void writeVec3s(ByteWriter& w, const std::vector<glm::vec3>& v) {
  static_assert(sizeof(glm::vec3) == 12, "glm::vec3 must be three packed floats");
  w.floats(reinterpret_cast<const float*>(v.data()), 3 * v.size());
}

glm::vec3 readVec3(ByteReader& r) {
  glm::vec3 v;
  r.floats(&v.x, 3);
  return v;
}

std::string text(glm::ivec3 v) {
  return std::to_string(v.x) + "x" + std::to_string(v.y) + "x" + std::to_string(v.z);
}

/// Throws (naming the setting) unless the file's settings are the tracer's.
void checkSettings(ByteReader& r, const StreakTracer& tracer, const std::string& path) {
  const int period = r.integer<std::int32_t>();
  const auto interpolation = r.integer<std::uint32_t>();
  glm::ivec3 res;
  for (int a = 0; a < 3; ++a) res[a] = r.integer<std::int32_t>();
  float cellSize;
  r.floats(&cellSize, 1);
  const glm::vec3 origin = readVec3(r);
  std::array<std::uint8_t, 6> sides;
  r.bytes(sides.data(), sides.size());
  const StreakParams& p = tracer.params();
  const GridFrame& g = tracer.gridFrame();
  if (period != p.emissionPeriod)
    fail(path, "was written with emission_period " + std::to_string(period) +
                   "; the tracer has " + std::to_string(p.emissionPeriod));
  if (interpolation != std::uint32_t(p.interpolation))
    fail(path, "was written with another interpolation than the tracer's");
  if (res != g.resolution)
    fail(path, "has resolution " + text(res) + "; the tracer's domain has " + text(g.resolution));
  if (cellSize != g.cellSize || origin != g.origin)
    fail(path, "was written for another domain box (cell size or origin differ)");
  for (int s = 0; s < 6; ++s)
    if (sides[std::size_t(s)] != std::uint8_t(tracer.boundaries()[std::size_t(s)]))
      fail(path, "was written with other open/closed boundaries than the tracer's");
}

}  // namespace

void writeTracerState(const std::string& path, const StreakTracer& tracer, int frame) {
  const StreakTracerState& s = tracer.state();
  const GridFrame& g = tracer.gridFrame();
  const std::size_t sources = s.sources.size(), particles = s.positions.size();
  ByteWriter w;
  w.reserve(kHeaderSize + kPerSource * sources + kPerParticle * particles + kChecksumSize);
  w.bytes(kMagic, sizeof(kMagic));
  w.integer<std::uint32_t>(kVersion);
  w.integer<std::int32_t>(frame);
  w.integer<std::int32_t>(tracer.params().emissionPeriod);
  w.integer<std::uint32_t>(std::uint32_t(tracer.params().interpolation));
  for (int a = 0; a < 3; ++a) w.integer<std::int32_t>(g.resolution[a]);
  w.floats(&g.cellSize, 1);
  w.floats(&g.origin.x, 3);
  for (Boundary b : tracer.boundaries()) w.integer<std::uint8_t>(std::uint8_t(b));
  w.integer<std::int64_t>(s.steps);
  w.integer<std::int32_t>(s.emissions);
  w.integer<std::uint64_t>(sources);
  w.integer<std::uint64_t>(particles);
  w.integer<std::int64_t>(s.lastEmissionStep);
  w.integer<std::uint8_t>(s.emitting ? 1 : 0);
  for (const PointSource& p : s.sources) {
    w.floats(&p.position.x, 3);
    w.integer<std::int32_t>(p.group);
    w.floats(&p.velocity.x, 3);
  }
  writeVec3s(w, s.positions);
  w.floats(s.density.data(), particles);
  w.bytes(s.outside.data(), particles);
  writeVec3s(w, s.exitVelocity);
  w.checksum();
  writeFileAtomic(path, w.buffer(), kKind);
}

int readTracerState(const std::string& path, StreakTracer& tracer) {
  const std::vector<unsigned char> buf =
      readFileChecked(path, kHeaderSizeV1 + kChecksumSize, kMaxFileSize, kKind);
  ByteReader r(buf.data(), buf.size(), kKind, path);
  const std::uint32_t version = r.header(kMagic, sizeof(kMagic), kOldestVersion, kVersion);
  const std::size_t headerSize = version == 1 ? kHeaderSizeV1 : kHeaderSize;
  if (!r.checksumMatches()) fail(path, "is corrupt (checksum mismatch)");
  const int frame = r.integer<std::int32_t>();
  checkSettings(r, tracer, path);

  StreakTracerState s;
  s.steps = r.integer<std::int64_t>();
  s.emissions = r.integer<std::int32_t>();
  const std::uint64_t sources = r.integer<std::uint64_t>();
  const std::uint64_t particles = r.integer<std::uint64_t>();
  // Both counts must fit in the file before anything is allocated from them (and each bound
  // keeps the size sum below from overflowing).
  if (sources > buf.size() / kPerSource || particles > buf.size() / kPerParticle ||
      headerSize + kPerSource * sources + kPerParticle * particles + kChecksumSize != buf.size())
    fail(path, "has " + std::to_string(buf.size()) + " bytes; " + std::to_string(sources) +
                   " sources and " + std::to_string(particles) +
                   " particles do not fill it exactly (truncated or corrupt)");
  if (version == 1) {  // every instant emitted: the youngest row is the last instant's
    s.lastEmissionStep = s.steps / tracer.params().emissionPeriod * tracer.params().emissionPeriod;
  } else {
    s.lastEmissionStep = r.integer<std::int64_t>();
    const auto emitting = r.integer<std::uint8_t>();
    if (emitting > 1) fail(path, "is corrupt (emitting flag " + std::to_string(emitting) + ")");
    s.emitting = emitting == 1;
  }
  s.sources.resize(std::size_t(sources));
  for (PointSource& p : s.sources) {
    p.position = readVec3(r);
    p.group = r.integer<std::int32_t>();
    p.velocity = readVec3(r);
  }
  const std::size_t m = std::size_t(particles);
  s.positions.resize(m);
  r.floats(reinterpret_cast<float*>(s.positions.data()), 3 * m);
  s.density.resize(m);
  r.floats(s.density.data(), m);
  s.outside.resize(m);
  r.bytes(s.outside.data(), m);
  s.exitVelocity.resize(m);
  r.floats(reinterpret_cast<float*>(s.exitVelocity.data()), 3 * m);
  if (r.remaining() != kChecksumSize) fail(path, "is corrupt (unexpected trailing bytes)");
  try {
    tracer.setState(std::move(s));
  } catch (const std::invalid_argument& e) {
    fail(path, std::string("is corrupt: ") + e.what());
  }
  return frame;
}

}  // namespace plume
