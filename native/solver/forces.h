#pragma once
/// \file forces.h
/// External forces of the smoke step: buoyancy and vorticity confinement (Fedkiw, Stam & Jensen
/// 2001 eqs. 8, 10, 11) and wind.

#include "core/grid3.h"
#include "core/mac_grid3.h"
#include "solver/smoke_params.h"

namespace plume {

/// Buoyancy f = -g (α ρ + β (T - T_amb)) added to every face between two fluid cells; ρ and T
/// are averaged from the two cells the face separates. cellTypes == nullptr: every cell is
/// fluid (so are they in the functions below).
void addBuoyancy(MacGrid3& velocity, const ScalarGrid& density, const ScalarGrid& temperature,
                 const FlagGrid* cellTypes, const SmokeParams& params, float dt);

/// Wind: u += dt k_w (u_wind - u) on fluid faces, with u_wind the constant params.wind or the
/// per-cell `field` (averaged to faces) when it is not empty.
void addWind(MacGrid3& velocity, const VectorGrid& field, const FlagGrid* cellTypes,
             const SmokeParams& params, float dt);

/// Vorticity confinement: ω = ∇ × u, N = ∇|ω| / |∇|ω||, f = ε Δx (N × ω) (Fedkiw 2001 eq. 11),
/// computed at cell centres and averaged to faces. `omega`, `force` and `magnitude` (|ω|) are
/// scratch grids sized like the cells.
void addVorticityConfinement(MacGrid3& velocity, const FlagGrid* cellTypes, float epsilon,
                             float cellSize, float dt, VectorGrid& omega, VectorGrid& force,
                             ScalarGrid& magnitude);

}  // namespace plume
