#pragma once
/// \file advection.h
/// Semi-Lagrangian advection (Stam 1999), BFECC (Kim, Liu, Llamas & Rossignac 2005) and
/// MacCormack (Selle, Fedkiw, Kim, Liu & Rossignac 2008), the last two with a clamp limiter, for
/// cell-centred scalars and the staggered velocity components.
///
/// Speed: back-traces are computed once per grid layout and stored split (cell + fractions, see
/// SamplePoints), so every field on the layout (density, temperature, fuel and soot share one
/// trace) and every pass of BFECC / MacCormack reuses the same weights; the fields of a layout
/// are carried together, run by run, so the weights are read once per pass for all of them.
/// Scalar fields skip the blocks of cells that are far from any smoke (their value stays the
/// background value exactly).

#include "core/grid3.h"
#include "core/mac_grid3.h"
#include "core/sample_points.h"
#include "core/sampling.h"
#include "solver/back_trace.h"
#include "solver/block_mask.h"
#include "solver/smoke_params.h"

namespace plume {

/// Carries grids through a velocity field. Owns the traces and scratch BFECC needs, sized once.
///
/// Use: trace() for a layout, then advect() the fields of that layout.
class Advector {
 public:
  /// One field advect() carries: src into dst (dst must not alias src), and its value in clean
  /// air, which it keeps outside the active blocks of the mask and finds beyond the open sides
  /// given to trace() (inflow.h); `ambient`, when given, holds a value of the air beyond those
  /// sides per sample instead (a wind field).
  struct Field {
    const ScalarGrid* src;
    ScalarGrid* dst;
    float background;
    const ScalarGrid* ambient = nullptr;
  };
  /// Most fields advect() carries in one call (density, temperature, fuel, soot).
  static constexpr std::size_t kMaxFields = 4;

  /// Reserves traces for grids of up to `count` samples and the scratch of `scheme` for up to
  /// `fields` fields of that size (no allocation afterwards).
  void reserve(std::size_t count, std::size_t fields = 1, Advection scheme = Advection::Bfecc);

  /// Traces every sample of a grid of `size` whose sample (0,0,0) sits at `offset`: back by Δt
  /// (and forth by Δt for BFECC and MacCormack) through `velocity` with the trace `order`, only
  /// in the active blocks of `mask` (nullptr = everywhere). Back-traces that end past one of
  /// `openSides` (openSides() mask) read the air outside (inflow.h); past other sides they are
  /// clamped onto the side.
  void trace(const MacGrid3& velocity, glm::ivec3 size, glm::vec3 offset, float dt, float cellSize,
             Advection scheme, const BlockMask* mask, Trace order = Trace::Midpoint,
             std::uint8_t openSides = 0);

  /// Each field's dst = its src advected with the last trace(). With BFECC: φ̂ = A(φ),
  /// φ̄ = A⁻¹(φ̂), result = A(φ + ½(φ - φ̄)) clamped to the range of φ around the back-traced
  /// point. With MacCormack: result = φ̂ + ½(φ - φ̄), clamped the same way (two passes, not
  /// three). Both fall back to the semi-Lagrangian value where the back-trace ends past an open
  /// side. Every src must have the traced size; at most kMaxFields (and what reserve() gave).
  void advect(const Field* fields, std::size_t count, Interpolation interpolation,
              const BlockMask* mask);
  /// advect() of one field.
  void advect(const ScalarGrid& src, ScalarGrid& dst, Interpolation interpolation,
              const BlockMask* mask, float background, const ScalarGrid* ambient = nullptr);

 private:
  BackTracer mTracer;
  ScalarGrid mForward[kMaxFields], mBackward[kMaxFields];
  CleanStencils mClean[kMaxFields];  ///< of the fields a cubic pass reads
  SamplePoints mBack, mFore;  ///< traced positions in the grid's index space, split
  Advection mScheme = Advection::SemiLagrangian;
};

}  // namespace plume
