#pragma once
/// \file birth_spacing.h
/// Birth with a spacing ([Cartoon Smoke] §2.2 last paragraph, §2.3): the paper gives a new
/// particle to every empty cell denser than ρ_birth, so on a grid finer than the stencils the
/// newborns overlap into one smooth blob. With birthSpacing σ > 0 a candidate cell c keeps its
/// newborn only when no particle (survivor, emitted this frame or born before it) lies closer than
///   r(c) = σ · s(ρ_c),   s = the §2.3 size ramp at the cell's density,
/// to the newborn's position, so the newborns of a dense region stay apart like puffs.
///
/// Deterministic at any thread count: the grid is cut into blocks of B cells per axis with
/// B·Δx >= the largest r, the blocks are visited in 8 phases by the parity of their block
/// coordinates (two blocks of one phase are a whole block apart, so they never see each other's
/// newborns), the blocks of a phase in parallel, the cells of a block in index order.

#include "solver/emitters.h"
#include "toon/toon_params.h"

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

namespace plume {

/// Scratch memory of spaceBirths(), kept between frames.
struct BirthSpacingScratch {
  std::vector<std::uint32_t> cellStart;      ///< per cell + 1: first particle in cellParticles
  std::vector<std::uint32_t> cellParticles;  ///< particle indices sorted by cell
  std::vector<std::uint32_t> particleCell;   ///< per particle: its cell, or ~0u outside the box
  std::vector<int> blocks;                   ///< the blocks of one phase
};

/// §2.3 birth spacing: `wanted` (one byte per cell of `grid`, 1 for a candidate: dense and
/// empty) keeps 1 only on the candidates whose newborn - at toon::birthPosition(params.seed,
/// frame, ...) - has no particle of `positions` and no kept newborn closer than
/// params.birthSpacing · params.rampSize(density of the cell); the others become 0. Does
/// nothing when params.birthSpacing is 0 (the paper's rule).
void spaceBirths(const ToonParams& params, const GridFrame& grid, const float* density,
                 const std::vector<glm::vec3>& positions, std::int64_t frame,
                 std::vector<std::uint8_t>& wanted, BirthSpacingScratch& scratch);

/// Cells per block side of spaceBirths(): the smallest B >= 1 with B·Δx >= σ · max(s0, s1).
int birthSpacingBlock(const ToonParams& params, float cellSize);

}  // namespace plume
