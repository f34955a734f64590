#include "solver/turbulence.h"

#include "core/parallel.h"
#include "solver/pressure.h"
#include "solver/source_noise.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace plume {
namespace {

/// Noise streams of g's three components, apart from the sources' (one stream per source).
constexpr std::uint64_t kTurbulenceStream = 0x7B0B0000ull;

/// Longest lattice row: nodes = ceil(size / spacing) + 3 with spacing >= Δx, and at most 1024
/// cells per axis (smokeSettingRanges()).
constexpr int kMaxLatticeRow = 1024 + 4;

/// Fills the lattice with g at time t: three independent noise values mapped to [-1, 1].
void fillLattice(const SmokeParams& p, double time, TurbulenceLattice& lattice) {
  const float spacing = std::max(p.cellSize, 0.25f * p.turbulenceScale);
  const glm::vec3 size = p.size();
  // Nodes from one spacing below the domain's corner to one above its far corner, so every face
  // has a whole lattice cell around it.
  const glm::ivec3 nodes = glm::ivec3(glm::ceil(size / spacing)) + 3;
  if (nodes.x > kMaxLatticeRow)
    throw std::logic_error("turbulence lattice rows longer than the resolution allows");
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

/// Position of lattice coordinate q (in node spacings) as (lower node, fraction), clamped so
/// both nodes exist.
inline void latticeCell(float q, int nodes, int& lower, float& fraction) {
  lower = std::min(std::max(int(std::floor(q)), 0), nodes - 2);
  fraction = std::min(std::max(q - float(lower), 0.f), 1.f);
}

}  // namespace

void addTurbulence(MacGrid3& velocity, const FlagGrid* types, const SmokeParams& p, double time,
                   float dt, TurbulenceLattice& lattice) {
  if (p.turbulence == 0.f) return;
  fillLattice(p, time, lattice);
  const glm::ivec3 n = velocity.cells();
  const glm::ivec3 nodes = lattice.g.size();
  const float push = dt * p.turbulence;
  const float toLattice = p.cellSize / lattice.spacing;
  const glm::vec3 offset = (p.origin - lattice.origin) / lattice.spacing;
  for (int a = 0; a < 3; ++a) {
    ScalarGrid& comp = velocity.component(a);
    const glm::ivec3 fs = comp.size();
    const std::size_t stride =
        a == 0 ? 1 : (a == 1 ? std::size_t(n.x) : std::size_t(n.x) * std::size_t(n.y));
    // Face (i, j, k) of component a lies at origin + Δx (i, j, k) + Δx/2 on the other axes;
    // the faces on the domain's sides are left to the boundary conditions.
    const glm::vec3 half(a == 0 ? 0.f : 0.5f, a == 1 ? 0.f : 0.5f, a == 2 ? 0.f : 0.5f);
    const int i0 = a == 0 ? 1 : 0, i1 = a == 0 ? n.x : fs.x;
    parallelFor(0, fs.z, [&](int k) {
      if (a == 2 && (k == 0 || k == n.z)) return;
      int kz;
      float fz;
      latticeCell(offset.z + (float(k) + half.z) * toLattice, nodes.z, kz, fz);
      float line[kMaxLatticeRow];  // g_a along the lattice's x at this face row's y and z
      for (int j = 0; j < fs.y; ++j) {
        if (a == 1 && (j == 0 || j == n.y)) continue;
        int jy;
        float fy;
        latticeCell(offset.y + (float(j) + half.y) * toLattice, nodes.y, jy, fy);
        for (int x = 0; x < nodes.x; ++x) {
          const float g00 = lattice.g(x, jy, kz)[a], g10 = lattice.g(x, jy + 1, kz)[a];
          const float g01 = lattice.g(x, jy, kz + 1)[a], g11 = lattice.g(x, jy + 1, kz + 1)[a];
          const float lo = g00 + fy * (g10 - g00), hi = g01 + fy * (g11 - g01);
          line[x] = lo + fz * (hi - lo);
        }
        float* u = &comp(0, j, k);
        const std::size_t row = std::size_t(n.x) * (std::size_t(j) + std::size_t(n.y) * k);
        for (int i = i0; i < i1; ++i) {
          // Cell (i, j, k) is above face (i, j, k) on every axis.
          if (types && ((*types)[row + i - stride] != kFluid || (*types)[row + i] != kFluid))
            continue;
          int ix;
          float fx;
          latticeCell(offset.x + (float(i) + half.x) * toLattice, nodes.x, ix, fx);
          u[i] += push * (line[ix] + fx * (line[ix + 1] - line[ix]));
        }
      }
    });
  }
}

}  // namespace plume
