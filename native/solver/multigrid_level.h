#pragma once
/// \file multigrid_level.h
/// One level of the MGPCG hierarchy (pressure.cpp): padded storage with one ghost cell on each
/// side, so the inner loops of the smoother and the residual need no bounds checks; and the
/// operators of the V-cycle on levels (multigrid_cycle.cpp): damped Jacobi smoothing,
/// restriction of the residual, prolongation of the correction.

#include "core/parallel.h"

#include <glm/glm.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace plume {
namespace detail {

/// One level of the hierarchy (padded storage, see the file comment).
struct Level {
  glm::ivec3 n{0};
  std::ptrdiff_t sy = 0, sz = 0;  ///< padded strides
  std::vector<float> diag;        ///< fluid neighbours + air neighbours; 0 on solid and ghosts
  std::vector<float> wInv;        ///< ω / diag on fluid cells, else 0
  std::vector<float> b, x, t;     ///< rhs, solution, scratch (level 0: CG's r, z and q)
  std::vector<float> rows;        ///< residual rows for the restriction, one per coarse slice

  std::size_t at(int i, int j, int k) const {
    return std::size_t((i + 1) + sy * (j + 1) + sz * (k + 1));
  }
  std::size_t padded() const { return std::size_t(n.x + 2) * (n.y + 2) * (n.z + 2); }
};

/// Jacobi damping ω. The smoother S = ω D⁻¹ is convergent in the A-norm (which makes the V-cycle
/// SPD) iff 2 D/ω - A is SPD; Gershgorin gives λ_max(D⁻¹A) <= 2, so any ω < 1 is safe. 6/7, the
/// optimal smoothing factor of the 3-D 7-point Laplacian, also measured best (vs 2/3 .. 0.9).
constexpr float kOmega = 6.f / 7.f;

/// fn(j, k) for every row of an n-cell level, slices in parallel.
template <typename RowFn>
void forRows(glm::ivec3 n, const RowFn& fn) {
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j) fn(j, k);
  });
}

/// v where `mask` (diag or wInv: 0 exactly on solid cells) is nonzero, else 0. Bitwise, since
/// GCC does not if-convert float compares (they may trap), which would keep loops scalar.
inline float keepIf(float mask, float v) {
  std::uint32_t vb, mb;
  std::memcpy(&vb, &v, 4);
  std::memcpy(&mb, &mask, 4);
  vb &= 0u - std::uint32_t(mb != 0);
  std::memcpy(&v, &vb, 4);
  return v;
}

/// Sum of the 6 neighbours of every cell in a padded row.
#define PLUME_NEIGHBOURS(v, i) (v[i - 1] + v[i + 1] + v[i - sy] + v[i + sy] + v[i - sz] + v[i + sz])

/// The first two Jacobi sweeps from x = 0, fused (pre-smoothing of a V-cycle level).
void smoothFromZero(Level& L);
/// One damped Jacobi sweep, x = x + W (b - A x).
void smooth(Level& L);
/// smooth() on the row at padded offset o, reading x and writing y (the preconditioner fuses it
/// with its dot products).
void smoothRow(const Level& L, const float* __restrict x, float* __restrict y, std::size_t o);
/// Coarse rhs C.b = R (F.b - A F.x), R = ½ × sum of the children.
void restrictResidual(Level& F, Level& C);
/// F.x += P C.x (piecewise constant), on fluid cells only.
void prolongAdd(Level& F, const Level& C);

}  // namespace detail
}  // namespace plume
