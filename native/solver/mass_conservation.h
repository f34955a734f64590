#pragma once
/// \file mass_conservation.h
/// Global mass correction after advection. Semi-Lagrangian and BFECC advection are not
/// conservative: in a closed box a plume can gain or lose 5-50% of its smoke over 100 steps at
/// CFL 1-2. The correction restores Σq to what it was, minus what left through open sides, while
/// keeping every value inside the range it already had (no new extrema).

#include "core/grid3.h"
#include "core/mac_grid3.h"
#include "solver/block_mask.h"
#include "solver/smoke_params.h"

namespace plume {

/// Every function takes the field's value in clean air, `background` (0 for ρ, F, S; T_amb for
/// temperature, whose "mass" is the heat Σ (T - T_amb)), and works on q - background.

/// Σ (q - background) over all cells (deterministic for any thread count).
double totalMass(const ScalarGrid& q, float background = 0.f);

/// Most fields totalMasses() and restoreMasses() take at once.
constexpr std::size_t kMaxMassFields = 4;

/// totalMass() of `count` grids of one size (at most kMaxMassFields) into masses[0 .. count-1],
/// and, when `peaks` is given, the largest q - background of each (at least 0), in one pass:
/// each sum is formed in the same order as alone (the same value), and the fields' independent
/// additions overlap, so the pass costs about what one field's costs.
/// With a mask, only its active blocks are read: every field must hold exactly its background
/// value outside them (as fields a BlockMask was built from, and their advected values, do).
void totalMasses(const ScalarGrid* const* q, const float* background, std::size_t count,
                 double* masses, float* peaks = nullptr, const BlockMask* mask = nullptr);

/// Mass that leaves through the open sides in dt: Σ over open boundary faces of q - background in
/// the boundary cell times the outward face velocity × dt / Δx (upwind; the air outside is clean
/// ambient air, so inflow brings nothing, see inflow.h).
double outflowMass(const ScalarGrid& q, const MacGrid3& velocity,
                   const std::array<Boundary, 6>& boundaries, float dt, float cellSize,
                   float background = 0.f);

/// outflowMass() of `count` grids (at most kMaxMassFields) into out[0 .. count-1], the same
/// values, each face's velocity read once for all of them.
void outflowMasses(const ScalarGrid* const* q, const float* background, std::size_t count,
                   const MacGrid3& velocity, const std::array<Boundary, 6>& boundaries, float dt,
                   float cellSize, double* out);

/// Scales e = q - background so that Σ e = target, without leaving [min(0, e), max e]: a surplus
/// is removed in proportion to e (e *= s, s < 1); a deficit is added in proportion to
/// e (1 - e/e_max) where e > 0, which is largest inside thin smoke and zero at the peak, so no
/// value passes e_max. Returns the mass still missing when the deficit is too large to restore
/// within those bounds.
double restoreMass(ScalarGrid& q, double target, float background = 0.f);

/// restoreMass() of `count` grids of one size (at most kMaxMassFields) at once, each with the
/// same result as alone, given their masses and peaks from totalMasses(); the passes over the
/// grids serve all of them. The masses still missing go to missing[0 .. count-1] when given.
/// With a mask, only its active blocks are read and changed (the same condition as
/// totalMasses(); the result is the same as without it).
void restoreMasses(ScalarGrid* const* q, const double* targets, const float* background,
                   std::size_t count, const double* masses, const float* peaks,
                   double* missing = nullptr, const BlockMask* mask = nullptr);

}  // namespace plume
