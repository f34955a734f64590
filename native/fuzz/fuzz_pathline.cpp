/// \file fuzz_pathline.cpp
/// Fuzz target of the pathline file reader (flowgraph/pathline_file.h), float32 and float16
/// samples alike (the header's flag picks): PathlineFile::open and readGroup of every node on
/// any bytes return groups of the header's layout with finite samples, or throw
/// std::runtime_error naming the file.

#include "fuzz_common.h"
#include "io/byte_buffer.h"

#include "flowgraph/pathline_file.h"

#include <cmath>
#include <cstring>

using namespace plume;

namespace {

void putU64(std::uint8_t* p, std::uint64_t v) {
  for (int b = 0; b < 8; ++b) p[b] = std::uint8_t((v >> (8 * b)) & 0xff);
}

/// Recomputes the three kinds of checksum of a pathline file (header, every node block, node
/// table) where the header's sizes allow; see fuzz_common.h for why.
void resignPathlines(std::uint8_t* data, std::size_t size) {
  constexpr std::size_t kHeader = 80;
  if (size < kHeader) return;
  putU64(data + 72, fnv1a64(data, 72));
  std::int32_t particles, samples;
  std::uint32_t flags, nodes;
  std::memcpy(&flags, data + 12, 4);
  std::memcpy(&particles, data + 16, 4);
  std::memcpy(&samples, data + 20, 4);
  std::memcpy(&nodes, data + 60, 4);
  if (particles < 1 || samples < 2) return;
  const std::uint64_t values = std::uint64_t(particles) * std::uint64_t(samples);
  if (values > kMaxPathlineSamples || nodes > kMaxPathlineNodes) return;
  const std::uint64_t block =
      8 + 12 * std::uint64_t(particles) + values * 5 * ((flags & 1u) ? 2 : 4);
  const std::uint64_t table = kHeader + block * nodes;
  if (table + 16 * std::uint64_t(nodes) + 8 != size) return;
  for (std::uint32_t k = 0; k < nodes; ++k)
    putU64(data + table + 16 * k + 8, pathlineChecksum(data + kHeader + block * k, block));
  putU64(data + size - 8, pathlineChecksum(data + table, 16 * std::size_t(nodes)));
}

}  // namespace

PLUME_FUZZ_RESIGNING_MUTATOR(resignPathlines)

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::TempInput input("pathline");
  const std::string& path = input.write(data, size);
  PathlineFile file;
  if (!fuzz::expectClean(path, [&] { file = PathlineFile::open(path); })) return 0;
  const PathlineLayout layout = file.layout();
  PathlineGroup g;
  for (int k = 0; k < file.nodeCount(); ++k) {
    if (!fuzz::expectClean(path, [&] { file.readGroup(k, g); })) continue;
    if (g.step != k || !(g.layout == layout) || g.start.size() != std::size_t(layout.particles) ||
        g.velocity.size() != layout.values() || g.density.size() != layout.values() ||
        g.temperature.size() != layout.values())
      fuzz::finding("readGroup returned a group that does not match the file's layout");
    for (std::size_t i = 0; i < layout.values(); ++i)
      if (!std::isfinite(g.velocity[i].x) || !std::isfinite(g.velocity[i].y) ||
          !std::isfinite(g.velocity[i].z) || !std::isfinite(g.density[i]) ||
          !std::isfinite(g.temperature[i]))
        fuzz::finding("readGroup returned a non-finite sample at node " + std::to_string(k));
    for (const glm::vec3& s : g.start)
      if (!std::isfinite(s.x) || !std::isfinite(s.y) || !std::isfinite(s.z))
        fuzz::finding("readGroup returned a non-finite start at node " + std::to_string(k));
  }
  return 0;
}
