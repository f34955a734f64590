#include "flowgraph/prepared_group.h"

#include "core/parallel.h"

#include <algorithm>

namespace plume {
namespace {

/// Particles per parallel task.
constexpr int kChunk = 512;

}  // namespace

std::size_t preparedGroupBytes(const PathlineLayout& layout) {
  return layout.values() * (2 * sizeof(glm::vec3) + 2 * sizeof(float));
}

std::size_t PreparedGroup::bytes() const {
  return (path.capacity() + velocity.capacity()) * sizeof(glm::vec3) +
         (density.capacity() + temperature.capacity()) * sizeof(float);
}

void prepareGroup(const PathlineGroup& g, PreparedGroup& out) {
  const PathlineLayout& layout = g.layout;
  const int L = layout.samples, P = layout.particles;
  const float half = 0.5f * layout.sampleDt;
  out.state = g.state;
  out.step = g.step;
  out.layout = layout;
  const std::size_t values = layout.values();
  out.path.resize(values);  // no allocation when a buffer of this layout is reused
  out.density.resize(values);
  out.temperature.resize(values);
  out.velocity.resize(values);
  const int chunks = (P + kChunk - 1) / kChunk;
  parallelFor(0, chunks, [&](int c) {
    const int begin = c * kChunk, end = std::min(P, begin + kChunk);
    // Particle-major samples in, sample-major out.
    for (int p = begin; p < end; ++p) {
      const std::size_t row = std::size_t(p) * std::size_t(L);
      const glm::vec3* u = g.velocity.data() + row;
      glm::vec3 x = g.start[std::size_t(p)];
      for (int a = 0; a < L; ++a) {
        const std::size_t at = std::size_t(a) * std::size_t(P) + std::size_t(p);
        out.path[at] = x;
        out.density[at] = g.density[row + std::size_t(a)];
        out.temperature[at] = g.temperature[row + std::size_t(a)];
        out.velocity[at] = u[a];
        // Eq. 13, pathline part, by the trapezoid rule between samples a and a + 1.
        if (a + 1 < L) x += half * (u[a] + u[a + 1]);
      }
    }
  });
}

}  // namespace plume
