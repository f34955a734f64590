#pragma once
/// \file mass_conservation.h
/// Global mass correction after advection. Semi-Lagrangian and BFECC advection are not
/// conservative: in a closed box a plume can gain or lose 5-50% of its smoke over 100 steps at
/// CFL 1-2. The correction restores Σq to what it was, minus what left through open sides, while
/// keeping every value inside the range it already had (no new extrema).

#include "core/grid3.h"
#include "core/mac_grid3.h"
#include "solver/smoke_params.h"

namespace plume {

/// Σ q over all cells (deterministic for any thread count).
double totalMass(const ScalarGrid& q);

/// Mass that leaves through the open sides in dt: Σ over open boundary faces of q in the
/// boundary cell times the outward face velocity × dt / Δx (upwind; the air outside is clean, so
/// inflow brings nothing).
double outflowMass(const ScalarGrid& q, const MacGrid3& velocity,
                   const std::array<Boundary, 6>& boundaries, float dt, float cellSize);

/// Scales q so that Σ q = target, without leaving [0, max q]: a surplus is removed in proportion
/// to q (q *= s, s < 1); a deficit is added in proportion to q (1 - q/q_max), which is largest
/// inside thin smoke and zero at the peak, so no value passes q_max. Returns the mass still
/// missing when the deficit is too large to restore within those bounds.
double restoreMass(ScalarGrid& q, double target);

}  // namespace plume
