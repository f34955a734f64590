/// \file state_file.cpp
/// Solver checkpoint. Layout (little-endian):
///   "PLUMESTATE" | u32 version = 1 | i32 frame | i32 nx, ny, nz | u32 grid count
///   per grid: u32 name length | name bytes | u64 value count | f32 values
///   u64 FNV-1a 64 checksum of every byte before it.
/// Reading checks the header against the solver, then the exact file size, then the checksum,
/// before any grid is parsed; the solver is only touched once everything has been read.

#include "solver/state_file.h"

#include "core/parallel.h"
#include "io/byte_buffer.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace plume {
namespace {

constexpr char kMagic[10] = {'P', 'L', 'U', 'M', 'E', 'S', 'T', 'A', 'T', 'E'};
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderSize = sizeof(kMagic) + 4 + 4 + 3 * 4 + 4;

/// The grids of the state, in file order.
struct GridRef {
  const char* name;
  ScalarGrid* grid;
};

std::vector<GridRef> stateGrids(SmokeSolver& s) {
  MacGrid3& vel = s.velocity();
  return {{"velocity_u", &vel.u()},       {"velocity_v", &vel.v()},
          {"velocity_w", &vel.w()},       {"density", &s.density()},
          {"temperature", &s.temperature()}, {"fuel", &s.fuel()},
          {"soot", &s.soot()},           {"flame", &s.flame()},
          {"pressure", &s.pressure()}};
}

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error("state file '" + path + "' " + what);
}

}  // namespace

void writeState(const std::string& path, const SmokeSolver& solver) {
  // stateGrids only reads through these pointers here.
  auto grids = stateGrids(const_cast<SmokeSolver&>(solver));
  const glm::ivec3 n = solver.params().resolution;
  // The file as pieces: small headers, then each grid's values straight from the solver (as
  // little-endian bytes: a copy only on big-endian hosts). No whole-file buffer: at 128³ that
  // was 75 MB allocated, page-faulted and copied for every checkpoint.
  std::vector<ByteWriter> heads(grids.size() + 1), bigEndian;
  std::vector<std::pair<const unsigned char*, std::size_t>> pieces;
  ByteWriter& w = heads[0];
  w.bytes(kMagic, sizeof(kMagic));
  w.integer<std::uint32_t>(kVersion);
  w.integer<std::int32_t>(solver.frame());
  w.integer<std::int32_t>(n.x);
  w.integer<std::int32_t>(n.y);
  w.integer<std::int32_t>(n.z);
  w.integer<std::uint32_t>(std::uint32_t(grids.size()));
  pieces.emplace_back(w.buffer().data(), w.buffer().size());
  const std::uint32_t one = 1;
  const bool little = *reinterpret_cast<const unsigned char*>(&one) == 1;
  if (!little) bigEndian.resize(grids.size());
  for (std::size_t g = 0; g < grids.size(); ++g) {
    ByteWriter& h = heads[g + 1];
    const std::size_t len = std::strlen(grids[g].name);
    h.integer<std::uint32_t>(std::uint32_t(len));
    h.bytes(grids[g].name, len);
    h.integer<std::uint64_t>(std::uint64_t(grids[g].grid->count()));
    pieces.emplace_back(h.buffer().data(), h.buffer().size());
    const float* values = grids[g].grid->data();
    const std::size_t count = grids[g].grid->count();
    if (little) {
      pieces.emplace_back(reinterpret_cast<const unsigned char*>(values), 4 * count);
    } else {
      bigEndian[g].floats(values, count);
      pieces.emplace_back(bigEndian[g].buffer().data(), bigEndian[g].buffer().size());
    }
  }
  writeFileAtomic(path, "state file", [&](std::ostream& out) {
    // The checksum (FNV-1a, one byte at a time) on one core while the other writes.
    std::uint64_t sum = 0;
    parallelFor(0, 2, [&](int task) {
      if (task == 0) {
        std::uint64_t h = fnv1a64(nullptr, 0);
        for (const auto& p : pieces) h = fnv1a64(p.first, p.second, h);
        sum = h;
      } else {
        for (const auto& p : pieces)
          out.write(reinterpret_cast<const char*>(p.first), std::streamsize(p.second));
      }
    });
    ByteWriter tail;
    tail.integer<std::uint64_t>(sum);
    out.write(reinterpret_cast<const char*>(tail.buffer().data()),
              std::streamsize(tail.buffer().size()));
  });
}

void readState(const std::string& path, SmokeSolver& solver) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) fail(path, "cannot be opened");
  const std::streamoff fileSize = in.tellg();
  if (fileSize < std::streamoff(kHeaderSize + 8)) fail(path, "is truncated (shorter than its header)");
  in.seekg(0);

  // Header first: it says whether this file can belong to this solver at all.
  std::vector<unsigned char> header(kHeaderSize);
  if (!in.read(reinterpret_cast<char*>(header.data()), std::streamsize(kHeaderSize)))
    fail(path, "cannot be read");
  ByteReader h(header.data(), header.size(), "state file", path);
  if (h.string(sizeof(kMagic)) != std::string(kMagic, sizeof(kMagic)))
    fail(path, "is not a Plume state file (bad magic)");
  const std::uint32_t version = h.integer<std::uint32_t>();
  if (version != kVersion) {
    std::ostringstream s;
    s << "has version " << version << "; this build reads version " << kVersion;
    fail(path, s.str());
  }
  const std::int32_t frame = h.integer<std::int32_t>();
  glm::ivec3 res;
  res.x = h.integer<std::int32_t>();
  res.y = h.integer<std::int32_t>();
  res.z = h.integer<std::int32_t>();
  const glm::ivec3 expect = solver.params().resolution;
  if (res != expect) {
    std::ostringstream s;
    s << "has resolution " << res.x << "x" << res.y << "x" << res.z << "; the domain has "
      << expect.x << "x" << expect.y << "x" << expect.z;
    fail(path, s.str());
  }
  auto grids = stateGrids(solver);
  const std::uint32_t gridCount = h.integer<std::uint32_t>();
  if (gridCount != grids.size()) {
    std::ostringstream s;
    s << "has " << gridCount << " grids; expected " << grids.size();
    fail(path, s.str());
  }
  // The exact size the solver's grids need; only then is anything allocated from the file.
  std::size_t expectedSize = kHeaderSize + 8;
  for (const GridRef& g : grids) expectedSize += 4 + std::strlen(g.name) + 8 + 4 * g.grid->count();
  if (std::size_t(fileSize) != expectedSize) {
    std::ostringstream s;
    s << "has " << fileSize << " bytes; a state of this domain has " << expectedSize
      << " (truncated or corrupt)";
    fail(path, s.str());
  }
  std::vector<unsigned char> buf(expectedSize);
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(buf.data()), std::streamsize(expectedSize)))
    fail(path, "cannot be read");

  ByteReader r(buf.data(), buf.size(), "state file", path);
  {
    ByteReader tail(buf.data() + expectedSize - 8, 8, "state file", path);
    if (fnv1a64(buf.data(), expectedSize - 8) != tail.integer<std::uint64_t>())
      fail(path, "is corrupt (checksum mismatch)");
  }
  r.string(kHeaderSize);
  std::vector<std::vector<float>> values(grids.size());
  for (std::size_t g = 0; g < grids.size(); ++g) {
    const std::uint32_t len = r.integer<std::uint32_t>();
    const std::string expectName = grids[g].name;
    if (len != expectName.size() || r.string(len) != expectName)
      fail(path, "is corrupt: expected grid '" + expectName + "' at this position");
    const std::uint64_t count = r.integer<std::uint64_t>();
    if (count != grids[g].grid->count()) {
      std::ostringstream s;
      s << "is corrupt: grid '" << expectName << "' has " << count << " values; expected "
        << grids[g].grid->count();
      fail(path, s.str());
    }
    values[g].resize(std::size_t(count));
    r.floats(values[g].data(), std::size_t(count));
    // A checksum only proves the bytes are the ones written: a NaN or infinity (a diverged
    // bake, a hand-made file) would become an index of INT_MIN in the next step's sampling.
    for (std::size_t i = 0; i < values[g].size(); ++i)
      if (!std::isfinite(values[g][i])) {
        std::ostringstream s;
        s << "is corrupt: grid '" << expectName << "' holds a non-finite value (" << values[g][i]
          << ") at index " << i;
        fail(path, s.str());
      }
  }
  if (r.position() + 8 != expectedSize) fail(path, "is corrupt (unexpected trailing bytes)");

  // Everything checked: commit.
  for (std::size_t g = 0; g < grids.size(); ++g) grids[g].grid->values().swap(values[g]);
  solver.setFrame(frame);
}

}  // namespace plume
