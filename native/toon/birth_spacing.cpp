/// \file birth_spacing.cpp
/// Birth spacing ([Cartoon Smoke] §2.3, see birth_spacing.h): a cell list of the particles,
/// then the candidate cells block by block in eight phases.

#include "toon/birth_spacing.h"

#include "core/parallel.h"
#include "toon/toon_random.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace plume {
namespace {

/// States of a cell in `wanted` while the phases run.
constexpr std::uint8_t kCandidate = 1;  ///< dense and empty, not visited yet
constexpr std::uint8_t kKept = 2;       ///< visited: its newborn stays

/// Sorts the particles inside the grid's box by cell (counting sort): the particles of cell c
/// are cellParticles[cellStart[c] .. cellStart[c + 1]). Particles outside the box are left out
/// (no smoke is simulated there; they are fading out).
void buildCellList(const GridFrame& grid, const std::vector<glm::vec3>& positions,
                   BirthSpacingScratch& s) {
  const glm::ivec3 n = grid.resolution;
  const std::size_t cells = std::size_t(n.x) * std::size_t(n.y) * std::size_t(n.z);
  const float inv = 1.f / grid.cellSize;
  const glm::vec3 hi = grid.origin + glm::vec3(n) * grid.cellSize;
  const std::uint32_t outside = ~0u;
  s.cellStart.assign(cells + 1, 0);
  s.particleCell.resize(positions.size());
  for (std::size_t m = 0; m < positions.size(); ++m) {
    const glm::vec3 x = positions[m];
    if (!glm::all(glm::greaterThanEqual(x, grid.origin)) || !glm::all(glm::lessThanEqual(x, hi))) {
      s.particleCell[m] = outside;  // also NaN
      continue;
    }
    const glm::ivec3 c =
        glm::clamp(glm::ivec3(glm::floor((x - grid.origin) * inv)), glm::ivec3(0), n - 1);
    const std::uint32_t cell =
        std::uint32_t(c.x + n.x * (c.y + n.y * c.z));
    s.particleCell[m] = cell;
    ++s.cellStart[std::size_t(cell) + 1];
  }
  for (std::size_t c = 1; c <= cells; ++c) s.cellStart[c] += s.cellStart[c - 1];
  s.cellParticles.resize(s.cellStart[cells]);
  // Fill with cellStart[c] as the cursor of cell c, which ends at the start of c + 1; then shift.
  for (std::size_t m = 0; m < positions.size(); ++m)
    if (s.particleCell[m] != outside) s.cellParticles[s.cellStart[s.particleCell[m]]++] = std::uint32_t(m);
  for (std::size_t c = cells; c > 0; --c) s.cellStart[c] = s.cellStart[c - 1];
  s.cellStart[0] = 0;
}

}  // namespace

int birthSpacingBlock(const ToonParams& params, float cellSize) {
  // B = floor(r / Δx) + 1 > r / Δx: two blocks of one phase are more than r apart (even when
  // the float r of a cell rounds above the double one here).
  const double r = double(params.birthSpacing) * double(std::max(params.sizeLow, params.sizeHigh));
  return int(std::floor(r / double(cellSize))) + 1;
}

void spaceBirths(const ToonParams& params, const GridFrame& grid, const float* density,
                 const std::vector<glm::vec3>& positions, std::int64_t frame,
                 std::vector<std::uint8_t>& wanted, BirthSpacingScratch& scratch) {
  if (!(params.birthSpacing > 0.f)) return;
  if (std::find(wanted.begin(), wanted.end(), kCandidate) == wanted.end()) return;
  buildCellList(grid, positions, scratch);
  const glm::ivec3 n = grid.resolution;
  const std::size_t nx = std::size_t(n.x), nxy = nx * std::size_t(n.y);
  const float inv = 1.f / grid.cellSize;
  const int B = birthSpacingBlock(params, grid.cellSize);
  const glm::ivec3 blocks = (n + B - 1) / B;

  // Whether a particle or a kept newborn lies closer than r to p (p in cell `self`).
  auto crowded = [&](glm::vec3 p, float r, std::size_t self) {
    const float r2 = r * r;
    const glm::ivec3 lo = glm::max(glm::ivec3(glm::floor((p - r - grid.origin) * inv)), glm::ivec3(0));
    const glm::ivec3 hi = glm::min(glm::ivec3(glm::floor((p + r - grid.origin) * inv)), n - 1);
    for (int k = lo.z; k <= hi.z; ++k)
      for (int j = lo.y; j <= hi.y; ++j)
        for (int i = lo.x; i <= hi.x; ++i) {
          const std::size_t c = std::size_t(i) + nx * std::size_t(j) + nxy * std::size_t(k);
          for (std::uint32_t q = scratch.cellStart[c]; q < scratch.cellStart[c + 1]; ++q) {
            const glm::vec3 d = positions[scratch.cellParticles[q]] - p;
            if (glm::dot(d, d) < r2) return true;
          }
          // A newborn kept earlier: in this block before `self`, or in a block of an earlier
          // phase (blocks of later phases still hold candidates, never kKept).
          if (c != self && wanted[c] == kKept) {
            const glm::vec3 d = toon::birthPosition(params.seed, frame, grid, {i, j, k}, c) - p;
            if (glm::dot(d, d) < r2) return true;
          }
        }
    return false;
  };

  for (int phase = 0; phase < 8; ++phase) {
    const glm::ivec3 parity(phase & 1, (phase >> 1) & 1, (phase >> 2) & 1);
    scratch.blocks.clear();
    for (int bz = parity.z; bz < blocks.z; bz += 2)
      for (int by = parity.y; by < blocks.y; by += 2)
        for (int bx = parity.x; bx < blocks.x; bx += 2)
          scratch.blocks.push_back(bx + blocks.x * (by + blocks.y * bz));
    parallelFor(0, int(scratch.blocks.size()), [&](int q) {
      const int b = scratch.blocks[std::size_t(q)];
      const glm::ivec3 first =
          B * glm::ivec3(b % blocks.x, (b / blocks.x) % blocks.y, b / (blocks.x * blocks.y));
      const glm::ivec3 last = glm::min(first + B, n);
      for (int k = first.z; k < last.z; ++k)
        for (int j = first.y; j < last.y; ++j)
          for (int i = first.x; i < last.x; ++i) {
            const std::size_t c = std::size_t(i) + nx * std::size_t(j) + nxy * std::size_t(k);
            if (wanted[c] != kCandidate) continue;
            const glm::vec3 p = toon::birthPosition(params.seed, frame, grid, {i, j, k}, c);
            const float r = params.birthSpacing * params.rampSize(density[c]);
            wanted[c] = crowded(p, r, c) ? 0 : kKept;
          }
    });
  }
  parallelFor(0, n.z, [&](int k) {
    std::uint8_t* w = wanted.data() + std::size_t(k) * nxy;
    for (std::size_t c = 0; c < nxy; ++c) w[c] = std::uint8_t(w[c] == kKept);
  });
}

}  // namespace plume
