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

/// Strength of vorticity confinement per cell: ε + ε_f min(F, 1), the uniform ε (Fedkiw 2001
/// eq. 11) plus Flame Vorticity ε_f where fuel F burns (Mantaflow's flame_vorticity, which adds
/// ε_f F to its uniform strength): a fire curls where it burns while its smoke stays smooth.
struct Confinement {
  float epsilon = 0.f;             ///< ε, everywhere
  float flameEpsilon = 0.f;        ///< ε_f, per unit of fuel (up to 1)
  const ScalarGrid* fuel = nullptr;  ///< F; nullptr or ε_f = 0: uniform ε only
  bool any() const { return epsilon != 0.f || (fuel && flameEpsilon != 0.f); }
};

/// Vorticity confinement: ω = ∇ × u, N = ∇|ω| / |∇|ω||, f = ε Δx (N × ω) (Fedkiw 2001 eq. 11),
/// with ε per cell from `strength`, computed at cell centres and averaged to faces. `omega`,
/// `force` and `magnitude` (|ω|) are scratch grids sized like the cells.
void addVorticityConfinement(MacGrid3& velocity, const FlagGrid* cellTypes,
                             const Confinement& strength, float cellSize, float dt,
                             VectorGrid& omega, VectorGrid& force, ScalarGrid& magnitude);

}  // namespace plume
