#pragma once
/// \file inflow.h
/// Open sides of the domain (Boundary::Open) as the inlet-outlet condition of production
/// solvers (OpenFOAM's inletOutlet and pressureInletOutletVelocity, Mantaflow's outflow cells
/// that are reset to clean air): what flows out leaves with zero gradient and p = 0 outside;
/// what flows in is the ambient air beyond the side: clean (ρ = F = S = 0), at T_amb, and still
/// (or moving with the wind, when there is one), so an inflow is only ever what the pressure
/// projection draws in (or the wind brings). Semi-Lagrangian advection reads that air through a
/// ghost layer of ambient values one sample past each open side (SamplePoints' ghost weights):
/// a sample whose back-trace ends past an open side takes the ambient value in proportion to how
/// far past it ends, as a trilinear sample of the padded grid would.
///
/// Clamping those traces onto the side instead (zero gradient for inflow too) let every inflow
/// face import the boundary cell's own value again and again: smoke touching an open side heated
/// the domain with no source, and an inward velocity there copied itself from step to step into a
/// self-sustaining jet (6-10 m/s into a still domain).

#include "core/grid3.h"
#include "core/sample_points.h"
#include "solver/block_mask.h"
#include "solver/smoke_params.h"

#include <array>
#include <cstdint>

namespace plume {

/// Mask (ghostSideBit()) of the open sides: those with a ghost layer of ambient air.
std::uint8_t openSides(const std::array<Boundary, 6>& boundaries);

/// grids[f](c) += w (ambient - grids[f](c)) for each of `count` grids at each sample c of the
/// grid traced into `back` whose back-trace ended past an open side (ghost weight w > 0), in the
/// active blocks of `mask`: the semi-Lagrangian step with the ghost layer. The ambient value of
/// grid f is ambientGrids[f](c) where that is given (a wind field), else ambient[f].
void blendInflow(ScalarGrid* const* grids, std::size_t count, const float* ambient,
                 const ScalarGrid* const* ambientGrids, const SamplePoints& back,
                 const BlockMask* mask);

/// dst[f](c) = src[f](c) at the same samples: BFECC and MacCormack fall back there to the
/// semi-Lagrangian value `src` (their error estimate and limiter see only the inside).
void copyInflow(ScalarGrid* const* src, ScalarGrid* const* dst, std::size_t count,
                const SamplePoints& back, const BlockMask* mask);

}  // namespace plume
