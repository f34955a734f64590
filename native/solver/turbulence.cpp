#include "solver/turbulence.h"

#include "core/parallel.h"
#include "solver/face_loops.h"
#include "solver/source_noise.h"

#include <algorithm>
#include <cmath>

namespace plume {
namespace {

/// Noise streams of g's three components, apart from the sources' (one stream per source).
constexpr std::uint64_t kTurbulenceStream = 0x7B0B0000ull;

/// Fills the lattice with g at time t: three independent noise values mapped to [-1, 1].
void fillLattice(const SmokeParams& p, double time, TurbulenceLattice& lattice) {
  const float spacing = std::max(p.cellSize, 0.25f * p.turbulenceScale);
  const glm::vec3 size = p.size();
  // Nodes from one spacing below the domain's corner to one above its far corner, so every face
  // has a whole lattice cell around it.
  const glm::ivec3 nodes = glm::ivec3(glm::ceil(size / spacing)) + 3;
  if (lattice.g.size() != nodes) lattice.g.resize(nodes);
  lattice.origin = p.origin - glm::vec3(spacing);
  lattice.spacing = spacing;
  const SourceNoise noise{1.f, p.turbulenceScale, p.turbulenceRate};
  parallelFor(0, nodes.z, [&](int k) {
    for (int j = 0; j < nodes.y; ++j)
      for (int i = 0; i < nodes.x; ++i) {
        const glm::vec3 x = lattice.origin + glm::vec3(i, j, k) * spacing;
        glm::vec3 g;
        for (int a = 0; a < 3; ++a)
          g[a] = 2.f * sourceNoiseValue(x, time, noise, p.seed, kTurbulenceStream + a) - 1.f;
        lattice.g(i, j, k) = g;
      }
  });
}

/// Component a of g at world point x, trilinear between the lattice's nodes.
float sampleLattice(const TurbulenceLattice& lattice, const glm::vec3& x, int a) {
  const glm::vec3 q = (x - lattice.origin) / lattice.spacing;
  const glm::ivec3 last = lattice.g.size() - 2;
  const glm::ivec3 c = glm::clamp(glm::ivec3(glm::floor(q)), glm::ivec3(0), last);
  const glm::vec3 f = glm::clamp(q - glm::vec3(c), 0.f, 1.f);
  float zs[2];
  for (int dz = 0; dz < 2; ++dz) {
    float ys[2];
    for (int dy = 0; dy < 2; ++dy) {
      const float lo = lattice.g(c.x, c.y + dy, c.z + dz)[a];
      const float hi = lattice.g(c.x + 1, c.y + dy, c.z + dz)[a];
      ys[dy] = lo + f.x * (hi - lo);
    }
    zs[dz] = ys[0] + f.y * (ys[1] - ys[0]);
  }
  return zs[0] + f.z * (zs[1] - zs[0]);
}

}  // namespace

void addTurbulence(MacGrid3& velocity, const FlagGrid* types, const SmokeParams& p, double time,
                   float dt, TurbulenceLattice& lattice) {
  if (p.turbulence == 0.f) return;
  fillLattice(p, time, lattice);
  const glm::ivec3 n = velocity.cells();
  const float push = dt * p.turbulence;
  for (int a = 0; a < 3; ++a)
    forEachFluidFace(velocity, types, a, [&](float& u, std::size_t, std::size_t hi) {
      // The face lies on the lower side of cell `hi`.
      const std::size_t nx = std::size_t(n.x), ny = std::size_t(n.y);
      glm::vec3 x = p.origin + p.cellSize * (glm::vec3(float(hi % nx), float((hi / nx) % ny),
                                                         float(hi / (nx * ny))) + 0.5f);
      x[a] -= 0.5f * p.cellSize;
      u += push * sampleLattice(lattice, x, a);
    });
}

}  // namespace plume
