/// \file multigrid_cycle.cpp
/// The operators of MGPCG's V-cycle (McAdams, Sifakis & Teran 2010; pressure.cpp runs the
/// cycle): damped Jacobi smoothing, restriction of the residual and piecewise constant
/// prolongation, on the padded levels of multigrid_level.h, row by row.

#include "solver/multigrid_level.h"

#include "core/cpu_features.h"
#include "core/parallel.h"

#include <algorithm>
#include <utility>

namespace plume {
namespace detail {
namespace {

/// Restriction weight. Level l's operator is the rediscretized stencil, i.e. H_l²·(-∇²) with
/// H_l = 2^l Δx (our fine operator is Δx²·(-∇²)). For a smooth error e with -∇²e = f the fine
/// residual is r_h ≈ h² f per cell, while the coarse equation A_H e_H = H² f = 4 h² f needs
/// 4 × (average of the 8 children) = ½ × (sum of the children). With piecewise constant
/// prolongation P this restriction is R = ½ Pᵀ, which keeps the V-cycle symmetric.
constexpr float kRestrict = 0.5f;

}  // namespace

/// smoothFromZero() on the row at padded offset o.
static PLUME_AVX2_CLONES void smoothFromZeroRow(Level& L, std::size_t o) {
  const std::ptrdiff_t sy = L.sy, sz = L.sz;
  const int nx = L.n.x;
  const float* __restrict b = L.b.data() + o;
  const float* __restrict w = L.wInv.data() + o;
  float* __restrict y = L.x.data() + o;
  for (int i = 0; i < nx; ++i) {
    const float s = w[i - 1] * b[i - 1] + w[i + 1] * b[i + 1] + w[i - sy] * b[i - sy] +
                    w[i + sy] * b[i + sy] + w[i - sz] * b[i - sz] + w[i + sz] * b[i + sz];
    y[i] = w[i] * ((2.f - kOmega) * b[i] + s);
  }
}

/// The first two Jacobi sweeps from x = 0, fused: x1 = W b, x2 = (1-ω) x1 + W (b + N x1)
/// = W ((2-ω) b + N (W b)), where N sums the neighbours.
void smoothFromZero(Level& L) {
  forRows(L.n, [&](int j, int k) { smoothFromZeroRow(L, L.at(0, j, k)); });
}

/// One damped Jacobi sweep on a row, y = x + W (b - A x) = (1-ω) x + W (b + N x).
PLUME_AVX2_CLONES void smoothRow(const Level& L, const float* __restrict x, float* __restrict y, std::size_t o) {
  const std::ptrdiff_t sy = L.sy, sz = L.sz;
  const float* __restrict b = L.b.data() + o;
  const float* __restrict w = L.wInv.data() + o;
  x += o;
  y += o;
  const int nx = L.n.x;
  for (int i = 0; i < nx; ++i)
    y[i] = (1.f - kOmega) * x[i] + w[i] * (b[i] + PLUME_NEIGHBOURS(x, i));
}

void smooth(Level& L) {
  forRows(L.n, [&](int j, int k) { smoothRow(L, L.x.data(), L.t.data(), L.at(0, j, k)); });
  std::swap(L.x, L.t);
}

/// s = b - A x on one row (0 on solid cells).
static PLUME_AVX2_CLONES void residualRow(const Level& L, std::size_t o, float* __restrict s) {
  const std::ptrdiff_t sy = L.sy, sz = L.sz;
  const float* __restrict x = L.x.data() + o;
  const float* __restrict b = L.b.data() + o;
  const float* __restrict d = L.diag.data() + o;
  const int nx = L.n.x;
  for (int i = 0; i < nx; ++i) s[i] = keepIf(d[i], b[i] - d[i] * x[i] + PLUME_NEIGHBOURS(x, i));
}

/// c_I += ½ (s_2I + s_2I+1): a residual row restricted along x.
static PLUME_AVX2_CLONES void restrictPairs(int n, const float* __restrict s, float* __restrict c) {
  for (int ic = 0; ic < n; ++ic) c[ic] += kRestrict * (s[2 * ic] + s[2 * ic + 1]);
}

/// Coarse rhs = R (b - A x), R = ½ × sum of the children (see kRestrict).
void restrictResidual(Level& F, Level& C) {
  parallelFor(0, C.n.z, [&](int kc) {
    float* s = F.rows.data() + std::size_t(kc) * (F.n.x + 2);
    s[F.n.x] = 0.f;  // odd nx: the last coarse cell has one child along x
    for (int jc = 0; jc < C.n.y; ++jc) std::fill_n(&C.b[C.at(0, jc, kc)], C.n.x, 0.f);
    for (int k = 2 * kc; k < std::min(2 * kc + 2, F.n.z); ++k)
      for (int j = 0; j < F.n.y; ++j) {
        residualRow(F, F.at(0, j, k), s);
        restrictPairs(C.n.x, s, &C.b[C.at(0, j >> 1, kc)]);
      }
  });
}

/// x_2I += e_I, x_2I+1 += e_I on fluid cells: a coarse row prolonged along x.
static PLUME_AVX2_CLONES void prolongPairs(int n, const float* __restrict e, const float* __restrict d,
                  float* __restrict x) {
  for (int ic = 0; ic < n / 2; ++ic) {
    x[2 * ic] += keepIf(d[2 * ic], e[ic]);
    x[2 * ic + 1] += keepIf(d[2 * ic + 1], e[ic]);
  }
  if (n & 1) x[n - 1] += keepIf(d[n - 1], e[n / 2]);
}

/// x += P e (piecewise constant), on fluid cells only.
void prolongAdd(Level& F, const Level& C) {
  forRows(F.n, [&](int j, int k) {
    const std::size_t o = F.at(0, j, k);
    prolongPairs(F.n.x, C.x.data() + C.at(0, j >> 1, k >> 1), F.diag.data() + o, F.x.data() + o);
  });
}

}  // namespace detail
}  // namespace plume
