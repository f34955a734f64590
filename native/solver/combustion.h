#pragma once
/// \file combustion.h
/// The combustion model of [Graph Fire Synthesis] §4.1: fuel burnt into soot and heat
/// (eqs. 3-5), cooling, conduction, and the divergence φ of the reaction zone (eq. 1).

#include "core/grid3.h"
#include "solver/smoke_params.h"

namespace plume {

/// Reaction over dt, integrated exactly per cell: burnt = F (1 - e^{-r dt}), F -= burnt,
/// S += k_S burnt (eq. 4), T += k_T burnt (eq. 5). Writes flame = min(1, F) before burning (the
/// reacting fuel, rendered as emission) and φ = expansion × burnt / dt into `divergence`.
void burnFuel(ScalarGrid& fuel, ScalarGrid& soot, ScalarGrid& temperature, ScalarGrid& flame,
              ScalarGrid& divergence, const FlagGrid& cellTypes, const SmokeParams& params,
              float dt);

/// Temperature cooling c ((T - T_0)/(T_max - T_0))^4 (eq. 5, after Feldman et al. 2003),
/// never below T_0, then conduction κ ΔT (explicit, sub-stepped to stay stable; solid cells and
/// closed sides are insulating, open sides are at T_0). `scratch` is sized like the cells.
void coolAndConduct(ScalarGrid& temperature, ScalarGrid& scratch, const FlagGrid& cellTypes,
                    const SmokeParams& params, float dt);

}  // namespace plume
