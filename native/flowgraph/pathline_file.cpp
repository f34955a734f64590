/// \file pathline_file.cpp
/// Pathline files ([Graph Fire Synthesis] §4.2): incremental writer and lazy reader.

#include "flowgraph/pathline_file.h"

#include "io/byte_buffer.h"

#include <openvdb/Types.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace plume {
namespace {

constexpr char kMagic[8] = {'P', 'L', 'U', 'M', 'E', 'P', 'T', 'H'};
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderBytes = 80;
constexpr std::uint32_t kIncomplete = 0xffffffffu;
constexpr std::size_t kEntryBytes = 16;
constexpr float kHalfMax = 65504.f;
const char* const kKind = "pathline file";

std::string named(const std::string& path) { return std::string(kKind) + " '" + path + "'"; }

/// The header of `info` with `nodes` and `tableOffset`, checksum included.
std::vector<unsigned char> headerBytes(const PathlineFileInfo& info, std::uint32_t nodes,
                                       std::uint64_t tableOffset) {
  ByteWriter w;
  w.reserve(kHeaderBytes);
  w.bytes(kMagic, sizeof kMagic);
  w.integer<std::uint32_t>(kVersion);
  w.integer<std::uint32_t>(info.float16 ? 1u : 0u);
  w.integer<std::int32_t>(info.layout.particles);
  w.integer<std::int32_t>(info.layout.samples);
  const float floats[] = {info.layout.sampleDt};
  w.floats(floats, 1);
  for (int a = 0; a < 3; ++a) w.integer<std::int32_t>(info.resolution[a]);
  const float geometry[] = {info.cellSize, info.origin.x, info.origin.y, info.origin.z};
  w.floats(geometry, 4);
  w.integer<std::int32_t>(info.nodesPerFrame);
  w.integer<std::uint32_t>(nodes);
  w.integer<std::uint64_t>(tableOffset);
  w.checksum();
  return std::move(w.buffer());
}

bool littleEndianHost() {
  const std::uint32_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

void putU16(unsigned char* p, std::uint16_t v) {
  p[0] = static_cast<unsigned char>(v & 0xff);
  p[1] = static_cast<unsigned char>(v >> 8);
}

std::uint16_t getU16(const unsigned char* p) { return std::uint16_t(p[0] | (p[1] << 8)); }

/// Encodes n floats at `out` (f32 or half), returning the end.
unsigned char* encode(const float* v, std::size_t n, bool half, unsigned char* out) {
  if (half) {
    for (std::size_t m = 0; m < n; ++m, out += 2) putU16(out, floatToHalf(v[m]));
    return out;
  }
  if (littleEndianHost()) {
    std::memcpy(out, v, 4 * n);
    return out + 4 * n;
  }
  for (std::size_t m = 0; m < n; ++m) {
    std::uint32_t u;
    std::memcpy(&u, v + m, 4);
    for (int b = 0; b < 4; ++b) *out++ = static_cast<unsigned char>((u >> (8 * b)) & 0xff);
  }
  return out;
}

const unsigned char* decode(const unsigned char* in, std::size_t n, bool half, float* v) {
  if (half) {
    for (std::size_t m = 0; m < n; ++m, in += 2) v[m] = halfToFloat(getU16(in));
    return in;
  }
  if (littleEndianHost()) {
    std::memcpy(v, in, 4 * n);
    return in + 4 * n;
  }
  for (std::size_t m = 0; m < n; ++m, in += 4) {
    const std::uint32_t u = std::uint32_t(in[0]) | (std::uint32_t(in[1]) << 8) |
                            (std::uint32_t(in[2]) << 16) | (std::uint32_t(in[3]) << 24);
    std::memcpy(v + m, &u, 4);
  }
  return in;
}

}  // namespace

std::uint64_t pathlineChecksum(const unsigned char* data, std::size_t size) {
  constexpr std::uint64_t kPrime = 0x100000001b3ull;
  std::uint64_t lane[4] = {0xcbf29ce484222325ull, 0x84222325cbf29ce4ull, 0x9ce484222325cbf2ull,
                           0x2325cbf29ce48422ull};
  std::size_t n = 0;
  for (; n + 32 <= size; n += 32)
    for (int l = 0; l < 4; ++l) {
      std::uint64_t word = 0;
      for (int b = 0; b < 8; ++b) word |= std::uint64_t(data[n + 8 * l + b]) << (8 * b);
      lane[l] = (lane[l] ^ word) * kPrime;
    }
  std::uint64_t h = fnv1a64(data + n, size - n, lane[0]);
  for (int l = 1; l < 4; ++l) h = (h ^ lane[l]) * kPrime;
  return (h ^ std::uint64_t(size)) * kPrime;
}

std::uint16_t floatToHalf(float value) {
  if (std::isnan(value)) value = 0.f;
  value = value > kHalfMax ? kHalfMax : (value < -kHalfMax ? -kHalfMax : value);
  return openvdb::math::half(value).bits();
}

float halfToFloat(std::uint16_t bits) {
  openvdb::math::half h;
  h.setBits(bits);
  return float(h);
}

// ---------------------------------------------------------------------------------------------

void PathlineFileInfo::validate() const {
  if (layout.particles < 1)
    throw std::invalid_argument("pathline particles must be >= 1 (got " +
                                std::to_string(layout.particles) + ")");
  if (layout.samples < 2)
    throw std::invalid_argument("pathline samples must be >= 2 (got " +
                                std::to_string(layout.samples) + ")");
  if (layout.values() > kMaxPathlineSamples)
    throw std::invalid_argument("pathline particles x samples must be <= " +
                                std::to_string(kMaxPathlineSamples) + " (got " +
                                std::to_string(layout.values()) + ")");
  if (!(layout.sampleDt > 0.f) || !std::isfinite(layout.sampleDt))
    throw std::invalid_argument("pathline sample_dt must be a finite number > 0");
  if (resolution.x < 1 || resolution.y < 1 || resolution.z < 1)
    throw std::invalid_argument("pathline resolution must be >= 1 cell per axis");
  if (!(cellSize > 0.f) || !std::isfinite(cellSize))
    throw std::invalid_argument("pathline cell_size must be a finite number > 0");
  if (!std::isfinite(origin.x) || !std::isfinite(origin.y) || !std::isfinite(origin.z))
    throw std::invalid_argument("pathline origin must be finite");
  if (nodesPerFrame < 1)
    throw std::invalid_argument("nodes_per_frame must be >= 1 (got " +
                                std::to_string(nodesPerFrame) + ")");
}

std::size_t PathlineFileInfo::blockBytes() const {
  const std::size_t p = std::size_t(layout.particles);
  return 8 + 12 * p + layout.values() * 5 * (float16 ? 2 : 4);
}

// ---------------------------------------------------------------------------------------------

PathlineFileWriter::PathlineFileWriter(const std::string& path, const PathlineFileInfo& info)
    : mPath(path), mInfo(info) {
  mInfo.validate();
  // The bake that writes this file replaces the older one: removing it first means a kill
  // leaves no complete-looking file of another bake behind.
  std::remove(mPath.c_str());
  errno = 0;
  mOut.open(partialPath(), std::ios::binary | std::ios::trunc);
  if (!mOut) fail("cannot be written: " + writeFailure(errno));
  const std::vector<unsigned char> header = headerBytes(mInfo, kIncomplete, 0);
  mOut.write(reinterpret_cast<const char*>(header.data()), std::streamsize(header.size()));
  if (!mOut) fail("cannot be written: " + writeFailure(errno));
  mOffset = header.size();
  mBlock.resize(mInfo.blockBytes());
}

PathlineFileWriter::~PathlineFileWriter() {
  if (!mClosed) mOut.close();
}

void PathlineFileWriter::fail(const std::string& what) {
  if (mOut.is_open()) mOut.close();
  mClosed = true;
  throw std::runtime_error(named(mPath) + " " + what);
}

void PathlineFileWriter::append(const PathlineGroup& g) {
  if (mFinished || mClosed) fail("is already finished or discarded; cannot append");
  if (!(g.layout == mInfo.layout))
    throw std::invalid_argument("pathline group layout (" + std::to_string(g.layout.particles) +
                                " particles, " + std::to_string(g.layout.samples) +
                                " samples) differs from the file's");
  if (g.step != nodeCount())
    throw std::invalid_argument("pathline group step " + std::to_string(g.step) +
                                " appended as node " + std::to_string(nodeCount()));
  const std::size_t p = std::size_t(mInfo.layout.particles), v = mInfo.layout.values();
  if (g.start.size() != p || g.velocity.size() != v || g.density.size() != v ||
      g.temperature.size() != v)
    throw std::invalid_argument("pathline group arrays do not match its layout");
  const bool half = mInfo.float16;
  unsigned char* out = mBlock.data();
  const std::uint32_t head[2] = {std::uint32_t(g.step), 0u};
  for (std::uint32_t h : head)
    for (int b = 0; b < 4; ++b) *out++ = static_cast<unsigned char>((h >> (8 * b)) & 0xff);
  out = encode(&g.start[0].x, 3 * p, false, out);
  out = encode(&g.velocity[0].x, 3 * v, half, out);
  out = encode(g.density.data(), v, half, out);
  out = encode(g.temperature.data(), v, half, out);
  errno = 0;
  mOut.write(reinterpret_cast<const char*>(mBlock.data()), std::streamsize(mBlock.size()));
  if (!mOut) fail("cannot be written: " + writeFailure(errno));
  mTable.push_back({mOffset, pathlineChecksum(mBlock.data(), mBlock.size())});
  mOffset += mBlock.size();
}

void PathlineFileWriter::finish() {
  if (mFinished) return;
  if (mClosed) fail("was discarded; cannot finish");
  ByteWriter t;
  for (const Entry& e : mTable) {
    t.integer<std::uint64_t>(e.offset);
    t.integer<std::uint64_t>(e.checksum);
  }
  t.integer<std::uint64_t>(pathlineChecksum(t.buffer().data(), t.buffer().size()));
  errno = 0;
  mOut.write(reinterpret_cast<const char*>(t.buffer().data()), std::streamsize(t.buffer().size()));
  // Only now does the header say "complete": a kill before this point leaves it "incomplete".
  const std::vector<unsigned char> header = headerBytes(mInfo, std::uint32_t(mTable.size()), mOffset);
  mOut.seekp(0);
  mOut.write(reinterpret_cast<const char*>(header.data()), std::streamsize(header.size()));
  mOut.flush();
  const bool ok = bool(mOut);
  int err = errno;
  mOut.close();
  if (ok && mOut.fail()) err = errno;
  mClosed = true;
  if (!ok || mOut.fail()) {
    std::remove(partialPath().c_str());
    throw std::runtime_error(named(mPath) + " cannot be written: " + writeFailure(err));
  }
  if (std::rename(partialPath().c_str(), mPath.c_str()) != 0) {
    std::remove(partialPath().c_str());
    throw std::runtime_error(named(mPath) + " cannot be written: renaming '" + partialPath() +
                             "' failed");
  }
  mFinished = true;
}

void PathlineFileWriter::discard() {
  if (mFinished) return;
  if (!mClosed) mOut.close();
  mClosed = true;
  std::remove(partialPath().c_str());
}

// ---------------------------------------------------------------------------------------------

PathlineFile PathlineFile::open(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error(named(path) + " cannot be opened");
  const std::streamoff end = in.tellg();
  if (end < 0) throw std::runtime_error(named(path) + " cannot be read");
  const std::uint64_t fileSize = std::uint64_t(end);
  if (fileSize < kHeaderBytes)
    throw std::runtime_error(named(path) + " is truncated (shorter than its header)");
  std::vector<unsigned char> head(kHeaderBytes);
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(head.data()), std::streamsize(head.size())))
    throw std::runtime_error(named(path) + " cannot be read");
  ByteReader r(head.data(), head.size(), kKind, path);
  r.header(kMagic, sizeof kMagic, kVersion);
  if (!r.checksumMatches()) throw std::runtime_error(named(path) + " is corrupt (header checksum)");
  PathlineFile f;
  f.mPath = path;
  PathlineFileInfo& info = f.mInfo;
  const auto flags = r.integer<std::uint32_t>();
  info.float16 = (flags & 1u) != 0;
  info.layout.particles = r.integer<std::int32_t>();
  info.layout.samples = r.integer<std::int32_t>();
  r.floats(&info.layout.sampleDt, 1);
  for (int a = 0; a < 3; ++a) info.resolution[a] = r.integer<std::int32_t>();
  float geometry[4];
  r.floats(geometry, 4);
  info.cellSize = geometry[0];
  info.origin = glm::vec3(geometry[1], geometry[2], geometry[3]);
  info.nodesPerFrame = r.integer<std::int32_t>();
  const auto nodes = r.integer<std::uint32_t>();
  const auto tableOffset = r.integer<std::uint64_t>();
  if (nodes == kIncomplete || tableOffset == 0)
    throw std::runtime_error(named(path) +
                             " is incomplete (the bake that wrote it did not finish)");
  try {
    info.validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(named(path) + " is corrupt (" + e.what() + ")");
  }
  if (nodes > kMaxPathlineNodes)
    throw std::runtime_error(named(path) + " is corrupt (" + std::to_string(nodes) + " nodes)");
  // Every size follows from the header; the file must be exactly that long.
  const std::uint64_t block = info.blockBytes();
  const std::uint64_t expectedTable = kHeaderBytes + block * nodes;
  const std::uint64_t expectedSize = expectedTable + kEntryBytes * nodes + 8;
  if (tableOffset != expectedTable)
    throw std::runtime_error(named(path) + " is corrupt (node table at the wrong offset)");
  if (fileSize < expectedSize)
    throw std::runtime_error(named(path) + " is truncated (" + std::to_string(fileSize) +
                             " bytes; its header needs " + std::to_string(expectedSize) + ")");
  if (fileSize > expectedSize)
    throw std::runtime_error(named(path) + " is corrupt (" + std::to_string(fileSize - expectedSize) +
                             " bytes after the node table)");
  std::vector<unsigned char> table(kEntryBytes * nodes + 8);
  in.seekg(std::streamoff(tableOffset));
  if (!in.read(reinterpret_cast<char*>(table.data()), std::streamsize(table.size())))
    throw std::runtime_error(named(path) + " cannot be read");
  ByteReader t(table.data(), table.size(), kKind, path);
  std::uint64_t stored = 0;
  for (int b = 0; b < 8; ++b) stored |= std::uint64_t(table[table.size() - 8 + std::size_t(b)]) << (8 * b);
  if (pathlineChecksum(table.data(), table.size() - 8) != stored)
    throw std::runtime_error(named(path) + " is corrupt (node table checksum)");
  f.mOffsets.resize(nodes);
  f.mChecksums.resize(nodes);
  for (std::uint32_t k = 0; k < nodes; ++k) {
    f.mOffsets[k] = t.integer<std::uint64_t>();
    f.mChecksums[k] = t.integer<std::uint64_t>();
    if (f.mOffsets[k] != kHeaderBytes + block * k)
      throw std::runtime_error(named(path) + " is corrupt (node " + std::to_string(k) +
                               " at the wrong offset)");
  }
  return f;
}

void PathlineFile::readGroup(int k, PathlineGroup& out, int state) const {
  if (k < 0 || k >= nodeCount())
    throw std::out_of_range(named(mPath) + " has no node " + std::to_string(k) + " (it has " +
                            std::to_string(nodeCount()) + ")");
  const std::size_t bytes = mInfo.blockBytes();
  // One scratch block per calling thread: readGroup() allocates nothing in steady state.
  thread_local std::vector<unsigned char> scratch;
  scratch.resize(bytes);
  {
    std::ifstream in(mPath, std::ios::binary);
    if (!in) throw std::runtime_error(named(mPath) + " cannot be opened");
    in.seekg(std::streamoff(mOffsets[std::size_t(k)]));
    if (!in.read(reinterpret_cast<char*>(scratch.data()), std::streamsize(bytes)))
      throw std::runtime_error(named(mPath) + " is truncated (node " + std::to_string(k) + ")");
  }
  if (pathlineChecksum(scratch.data(), bytes) != mChecksums[std::size_t(k)])
    throw std::runtime_error(named(mPath) + " is corrupt (node " + std::to_string(k) +
                             " checksum)");
  const std::uint32_t step = std::uint32_t(scratch[0]) | (std::uint32_t(scratch[1]) << 8) |
                             (std::uint32_t(scratch[2]) << 16) | (std::uint32_t(scratch[3]) << 24);
  if (step != std::uint32_t(k))
    throw std::runtime_error(named(mPath) + " is corrupt (node " + std::to_string(k) +
                             " says step " + std::to_string(step) + ")");
  const std::size_t p = std::size_t(mInfo.layout.particles), v = mInfo.layout.values();
  out.state = state;
  out.step = k;
  out.layout = mInfo.layout;
  out.start.resize(p);
  out.velocity.resize(v);
  out.density.resize(v);
  out.temperature.resize(v);
  const bool half = mInfo.float16;
  const unsigned char* in = scratch.data() + 8;
  in = decode(in, 3 * p, false, &out.start[0].x);
  in = decode(in, 3 * v, half, &out.velocity[0].x);
  in = decode(in, v, half, out.density.data());
  decode(in, v, half, out.temperature.data());
  // A checksum only proves the bytes are the ones written: a NaN or infinity (a hand-made or
  // damaged file; half NaN/inf bits) would move synthesized particles to non-finite positions
  // that become cell indices. x * 0 is 0 for finite x and NaN otherwise: one vectorized pass.
  float bad = 0.f;
  const auto sweep = [&bad](const float* a, std::size_t n) {
    for (std::size_t m = 0; m < n; ++m) bad += a[m] * 0.f;
  };
  sweep(&out.start[0].x, 3 * p);
  sweep(&out.velocity[0].x, 3 * v);
  sweep(out.density.data(), v);
  sweep(out.temperature.data(), v);
  if (bad != 0.f)
    throw std::runtime_error(named(mPath) + " is corrupt (node " + std::to_string(k) +
                             " holds a non-finite value)");
}

PathlineGroup PathlineFile::readGroup(int k, int state) const {
  PathlineGroup g;
  readGroup(k, g, state);
  return g;
}

}  // namespace plume
