#pragma once
/// \file band_solver.h
/// Exact solve on the coarsest multigrid level of the pressure solver.

#include "solver/multigrid_level.h"

#include <algorithm>
#include <cstddef>
#include <vector>

namespace plume {
namespace detail {

/// Direct solve on the coarsest level: banded Cholesky of the fluid cells ordered with the
/// longest axis slowest (bandwidth = product of the two shorter axes). A pivot that vanishes
/// (the last cell of a component with no air, e.g. the all-closed singular case) is dropped,
/// which pins that cell to 0: x = L⁺ᵀ L⁺ b stays symmetric positive semi-definite and solves
/// A x = b for any consistent b.
struct BandSolver {
  int n = 0, w = 0;
  std::vector<std::size_t> cells;  ///< padded index of each unknown
  std::vector<double> l;           ///< row i holds L(i, i-w .. i)
  std::vector<double> y;

  double& at(int i, int j) { return l[std::size_t(i) * (w + 1) + (w - (i - j))]; }

  static double cost(glm::ivec3 s) {
    int a[3] = {s.x, s.y, s.z};
    std::sort(a, a + 3);
    const double bw = double(a[0]) * a[1];
    return bw * bw * a[0] * a[1] * a[2];
  }

  /// Factors A of the level's fluid cells (L Lᵀ, band of width w).
  void build(const Level& L);
  /// L.x = A⁺ L.b.
  void solve(Level& L);
};

}  // namespace detail
}  // namespace plume
