#pragma once
/// \file pressure.h
/// Pressure projection's linear solve: conjugate gradients preconditioned by a multigrid V-cycle
/// (MGPCG, McAdams et al. 2010), with open (p = 0) or closed sides and solid cells.

#include "core/grid3.h"
#include "solver/smoke_params.h"

#include <array>
#include <memory>
#include <vector>

namespace plume {

/// Cell types of the pressure solve.
enum CellType : std::uint8_t { kFluid = 0, kSolid = 1 };

/// Result of one solve.
struct PressureStats {
  int iterations = 0;
  float relativeResidual = 0.f;  ///< |b - A p|_2 / |b|_2 at exit
};

/// Solves A p = b on the fluid cells, where for a fluid cell i
///   (A p)_i = Σ_{fluid n} (p_i - p_n) + Σ_{air n} p_i
/// over its 6 neighbours n: a fluid neighbour couples, a neighbour across an open side is air
/// (p = 0, Dirichlet), a solid cell or a closed side adds nothing (Neumann). A is the negated
/// Laplacian times Δx², symmetric positive (semi-)definite. Solid cells get p = 0.
/// When no side is open the system is singular: b is made mean-free over the fluid cells and p is
/// returned mean-free.
class PressureSolver {
 public:
  PressureSolver();
  ~PressureSolver();

  /// Builds the multigrid hierarchy and work buffers for these cell types and sides.
  /// Must be called again when the solid cells change; allocation happens only here.
  void setup(const FlagGrid& cellTypes, const std::array<Boundary, 6>& boundaries);

  /// Solves A p = b to |r| <= tolerance |b| or maxIterations. `pressure` is the initial guess
  /// on entry (warm start) and the solution on exit. Deterministic for any thread count.
  PressureStats solve(const ScalarGrid& rhs, ScalarGrid& pressure, float tolerance,
                      int maxIterations);

  /// y = A x (exposed for tests).
  void applyOperator(const ScalarGrid& x, ScalarGrid& y) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> mImpl;
};

}  // namespace plume
