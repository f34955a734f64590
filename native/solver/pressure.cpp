/// \file pressure.cpp
/// MGPCG (McAdams, Sifakis & Teran 2010): conjugate gradients on the 7-point pressure operator,
/// preconditioned by one symmetric multigrid V-cycle on a cell-centred hierarchy. The cycle's
/// smoothing and transfer operators are in multigrid_cycle.cpp.
///
/// Storage: every vector of the hierarchy is padded by one ghost cell on each side. Ghost cells
/// and solid cells hold 0 in every vector at all times and have diag = 0, so the inner loops need
/// no bounds checks and no branch on the cell type: a neighbour that is solid or outside the
/// domain contributes x_n = 0, and open sides are already counted in the diagonal.

#include "solver/pressure.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "core/cpu_features.h"
#include "core/huge_pages.h"
#include "core/parallel.h"
#include "solver/band_solver.h"
#include "solver/multigrid_level.h"

namespace plume {
namespace {

using detail::BandSolver;
using detail::Level;
using detail::forRows;
using detail::keepIf;
using detail::kOmega;
using detail::prolongAdd;
using detail::restrictResidual;
using detail::smooth;
using detail::smoothFromZero;
using detail::smoothRow;

// Pre- and post-smoothing sweeps are 2 each (equal counts keep the V-cycle symmetric): V(2,2)
// needed the least time per solve (V(1,1): 1.6x the iterations; V(3,3): about even).
constexpr int kMaxLevels = 16;
/// Coarsening stops before the smallest axis drops below this many cells...
constexpr int kMinCoarseCells = 4;
/// ...unless the banded Cholesky factor of the coarsest level would cost more than this many
/// flops (n w²), in which case coarsening continues (thin domains).
constexpr double kMaxBandFlops = 1.6e7;
/// Restarts of CG from the true residual (see solve()).
constexpr int kMaxRestarts = 2;
/// Rounding a float p changes A p by 2e-7 .. 3.4e-7 |p| (measured; ≈ √42 × the rms rounding
/// error), so the true relative residual cannot go much below that times |p|/|b|.
constexpr double kRoundOffFloor = 3e-7;

/// Σ a_i b_i (b = nullptr: Σ a_i): float products summed in double in four fixed lanes i mod 4
/// (deterministic; vectorized). The row kernels below (and those of multigrid_cycle.cpp) are
/// PLUME_AVX2_CLONES: the solve is
/// bound by these loops, AVX2 runs them about 20% faster, with the same values.
PLUME_AVX2_CLONES double dotRow(const float* a, const float* b, int n) {
  double s[4] = {0, 0, 0, 0};
  int i = 0;
  if (b)
    for (; i + 4 <= n; i += 4)
      for (int l = 0; l < 4; ++l) s[l] += double(a[i + l] * b[i + l]);
  else
    for (; i + 4 <= n; i += 4)
      for (int l = 0; l < 4; ++l) s[l] += a[i + l];
  for (; i < n; ++i) s[0] += double(a[i]) * (b ? b[i] : 1.f);
  return (s[0] + s[1]) + (s[2] + s[3]);
}

/// q = A d on a padded row (0 on solid cells).
PLUME_AVX2_CLONES void applyPaddedRow(int nx, std::ptrdiff_t sy, std::ptrdiff_t sz,
                                      const float* __restrict dd, const float* __restrict dg,
                                      float* __restrict qq) {
  for (int i = 0; i < nx; ++i) qq[i] = keepIf(dg[i], dg[i] * dd[i] - PLUME_NEIGHBOURS(dd, i));
}

/// CG's step on a row: p += α d (in double), r -= α q (q less its mean on fluid cells when the
/// system is singular).
PLUME_AVX2_CLONES void stepRow(int nx, double alpha, float alphaF, bool singular, float meanQ,
                               const float* __restrict dd, const float* __restrict qq,
                               const float* __restrict dg, float* __restrict rp,
                               double* __restrict pp) {
  for (int i = 0; i < nx; ++i) pp[i] += alpha * dd[i];
  if (singular)
    for (int i = 0; i < nx; ++i) rp[i] -= keepIf(dg[i], alphaF * (qq[i] - meanQ));
  else
    for (int i = 0; i < nx; ++i) rp[i] -= alphaF * qq[i];
}

/// d = z' + β d on a row (z' = z - mean on fluid cells when the system is singular).
PLUME_AVX2_CLONES void directionRow(int nx, float beta, bool singular, float meanZ,
                                    const float* __restrict z, const float* __restrict dg,
                                    float* __restrict dd) {
  if (singular)
    for (int i = 0; i < nx; ++i) dd[i] = keepIf(dg[i], z[i] - meanZ) + beta * dd[i];
  else
    for (int i = 0; i < nx; ++i) dd[i] = z[i] + beta * dd[i];
}

}  // namespace

struct PressureSolver::Impl {
  glm::ivec3 size{0};
  bool singular = false;  ///< no open side
  double fluidCount = 0;
  std::vector<Level> levels;
  BandSolver band;
  std::vector<float> d;         ///< CG search direction (padded)
  std::vector<double> pd;       ///< CG's p in double (unpadded): p's rounding does not add up
  std::vector<double> rowsD;    ///< one row of doubles per slice (true residual)
  std::vector<float> zeroRow;   ///< stands in for rows outside the domain (unpadded kernels)
  std::vector<double> partial;  ///< per-slice partial sums, 4 per slice

  void put(int k, double a, double b = 0.0, double c = 0.0) {
    partial[std::size_t(k) * 4] = a;
    partial[std::size_t(k) * 4 + 1] = b;
    partial[std::size_t(k) * 4 + 2] = c;
  }
  double sum(int comp) const {
    double s = 0.0;
    for (int k = 0; k < size.z; ++k) s += partial[std::size_t(k) * 4 + comp];
    return s;
  }
  std::size_t urow(int j, int k) const {
    return std::size_t(size.x) * (j + std::size_t(size.y) * k);
  }

  /// out = (A x) on one row of an unpadded grid x, in precision T. Neighbours are masked by the
  /// padded diag (0 on solid cells and outside), so x may hold anything on solid cells.
  template <typename T>
  void applyRow(const float* x, int j, int k, T* out) const {
    const Level& L = levels[0];
    const int nx = size.x;
    const std::ptrdiff_t sy = L.sy, sz = L.sz, uz = std::ptrdiff_t(nx) * size.y;
    const float* xc = x + urow(j, k);
    const float* xjm = j > 0 ? xc - nx : zeroRow.data();
    const float* xjp = j + 1 < size.y ? xc + nx : zeroRow.data();
    const float* xkm = k > 0 ? xc - uz : zeroRow.data();
    const float* xkp = k + 1 < size.z ? xc + uz : zeroRow.data();
    const float* d = L.diag.data() + L.at(0, j, k);
    auto cell = [&](int i, float xm, float xp) {
      auto sel = [](float m, float v) { return T(keepIf(m, v)); };
      const T s = sel(d[i - 1], xm) + sel(d[i + 1], xp) + sel(d[i - sy], xjm[i]) +
                  sel(d[i + sy], xjp[i]) + sel(d[i - sz], xkm[i]) + sel(d[i + sz], xkp[i]);
      return (T(d[i]) * sel(d[i], xc[i]) - s) * sel(d[i], 1.f) + T(0);  // + 0: no -0 on solids
    };
    out[0] = cell(0, 0.f, nx > 1 ? xc[1] : 0.f);
    for (int i = 1; i < nx - 1; ++i) out[i] = cell(i, xc[i - 1], xc[i + 1]);
    if (nx > 1) out[nx - 1] = cell(nx - 1, xc[nx - 2], 0.f);
  }

  /// V-cycle for level l's b into its x. Level 0 skips its last post-smoothing sweep, which
  /// precondition() fuses with the dot products.
  void vcycle(std::size_t l) {
    Level& L = levels[l];
    if (l + 1 == levels.size()) return band.solve(L);
    smoothFromZero(L);
    restrictResidual(L, levels[l + 1]);
    vcycle(l + 1);
    prolongAdd(L, levels[l + 1]);
    smooth(L);
    if (l > 0) smooth(L);
  }

  /// z = M r (level 0's x = M b); returns ρ = r·z' where z' = z - mean(z) on the fluid cells in the
  /// singular case (the projection itself is applied by updateDirection()).
  double precondition(float& meanZ) {
    Level& L0 = levels[0];
    vcycle(0);  // (a single level is solved exactly: the sweep below leaves it unchanged)
    const int nx = size.x;
    parallelFor(0, size.z, [&](int k) {
      double rz = 0.0, zs = 0.0, rs = 0.0;
      for (int j = 0; j < size.y; ++j) {
        const std::size_t o = L0.at(0, j, k);
        smoothRow(L0, L0.x.data(), L0.t.data(), o);
        const float* z = L0.t.data() + o;
        rz += dotRow(L0.b.data() + o, z, nx);
        if (singular) {
          zs += dotRow(z, nullptr, nx);
          rs += dotRow(L0.b.data() + o, nullptr, nx);
        }
      }
      put(k, rz, zs, rs);
    });
    std::swap(L0.x, L0.t);
    if (!singular) return sum(0);
    const double mean = sum(1) / fluidCount;
    meanZ = float(mean);
    return sum(0) - mean * sum(2);
  }

  /// d = z' + β d.
  void updateDirection(double beta, float meanZ) {
    const Level& L0 = levels[0];
    const float bt = float(beta);
    const int nx = size.x;
    forRows(size, [&](int j, int k) {
      const std::size_t o = L0.at(0, j, k);
      directionRow(nx, bt, singular, meanZ, L0.x.data() + o, L0.diag.data() + o, d.data() + o);
    });
  }

  /// Mean of an unpadded field over the fluid cells.
  float fluidMean(const float* f) {
    const Level& L0 = levels[0];
    parallelFor(0, size.z, [&](int k) {
      double s = 0.0;
      for (int j = 0; j < size.y; ++j) {
        const float* dg = L0.diag.data() + L0.at(0, j, k);
        const float* fr = f + urow(j, k);
        for (int i = 0; i < size.x; ++i) s += keepIf(dg[i], fr[i]);
      }
      put(k, s);
    });
    return fluidCount > 0 ? float(sum(0) / fluidCount) : 0.f;
  }

  /// p -= meanP on fluid cells and 0 on solid ones; then r = b' - A p evaluated in double (stored
  /// as float in level 0's b). Returns |r|², with |b'|² and |p|². b' = b - meanB on fluid cells.
  double residual(const float* b, float meanB, float* p, float meanP, double& bb, double& pp) {
    Level& L0 = levels[0];
    const int nx = size.x;
    forRows(size, [&](int j, int k) {
      const float* dg = L0.diag.data() + L0.at(0, j, k);
      float* pr = p + urow(j, k);
      for (int i = 0; i < nx; ++i) pr[i] = keepIf(dg[i], pr[i] - meanP);
    });
    parallelFor(0, size.z, [&](int k) {
      double sb[2] = {0, 0}, sr[2] = {0, 0};
      double* ap = rowsD.data() + std::size_t(k) * nx;
      for (int j = 0; j < size.y; ++j) {
        const float* br = b + urow(j, k);
        const float* dg = L0.diag.data() + L0.at(0, j, k);
        float* rp = L0.b.data() + L0.at(0, j, k);
        applyRow<double>(p, j, k, ap);
        for (int i = 0; i < nx; ++i) {  // two fixed lanes: deterministic and vectorizable
          const double bi = keepIf(dg[i], br[i] - meanB);
          const double ri = keepIf(dg[i], 1.f) * (bi - ap[i]);
          rp[i] = float(ri);
          sb[i & 1] += bi * bi;
          sr[i & 1] += ri * ri;
        }
      }
      put(k, sb[0] + sb[1], sr[0] + sr[1], dotRow(p + urow(0, k), p + urow(0, k), nx * size.y));
    });
    bb = sum(0);
    pp = sum(2);
    return sum(1);
  }

  /// Preconditioned CG from the residual r (level 0's b) until the recurrence |r|² <= target.
  /// p is accumulated in double and rounded once at the end.
  void conjugateGradients(float* p, double rr, double target, int maxIterations,
                          PressureStats& stats) {
    Level& L0 = levels[0];
    const int nx = size.x;
    const std::ptrdiff_t sy = L0.sy, sz = L0.sz;
    const std::size_t slice = std::size_t(size.x) * size.y;
    parallelFor(0, size.z,
                [&](int k) { std::copy_n(p + slice * k, slice, pd.data() + slice * k); });
    float meanZ = 0.f;
    double rho = precondition(meanZ);
    updateDirection(0.0, meanZ);
    while (rr > target && stats.iterations < maxIterations) {
      ++stats.iterations;
      // q = A d (in level 0's scratch vector), d·q and Σq.
      float* q = L0.t.data();
      parallelFor(0, size.z, [&](int k) {
        double dq = 0.0, qs = 0.0;
        for (int j = 0; j < size.y; ++j) {
          const std::size_t o = L0.at(0, j, k);
          const float* dd = d.data() + o;
          float* qq = q + o;
          applyPaddedRow(nx, sy, sz, dd, L0.diag.data() + o, qq);
          dq += dotRow(dd, qq, nx);
          if (singular) qs += dotRow(qq, nullptr, nx);
        }
        put(k, dq, qs);
      });
      const double dq = sum(0);
      if (!(dq > 0.0) || !(rho > 0.0)) break;  // converged to round-off (or breakdown)
      const double alpha = rho / dq;
      const float alphaF = float(alpha);
      // Singular case: Σ_fluid A d = 0 exactly, but not in float; projecting the mean out of q
      // keeps r in the range of A (else its null-space part stalls CG at the round-off level).
      const float meanQ = singular ? float(sum(1) / fluidCount) : 0.f;
      // p += α d, r -= α q, |r|².
      parallelFor(0, size.z, [&](int k) {
        double s = 0.0;
        for (int j = 0; j < size.y; ++j) {
          const std::size_t o = L0.at(0, j, k);
          float* rp = L0.b.data() + o;
          stepRow(nx, alpha, alphaF, singular, meanQ, d.data() + o, q + o, L0.diag.data() + o, rp,
                  pd.data() + urow(j, k));
          s += dotRow(rp, rp, nx);
        }
        put(k, s);
      });
      rr = sum(0);
      if (rr <= target) break;
      const double rhoNew = precondition(meanZ);
      updateDirection(rhoNew / rho, meanZ);
      rho = rhoNew;
    }
    parallelFor(0, size.z, [&](int k) {
      for (std::size_t c = slice * k; c < slice * (k + 1); ++c) p[c] = float(pd[c]);
    });
  }
};

PressureSolver::PressureSolver() : mImpl(std::make_unique<Impl>()) {}
PressureSolver::~PressureSolver() = default;

void PressureSolver::setup(const FlagGrid& cellTypes, const std::array<Boundary, 6>& boundaries) {
  Impl& m = *mImpl;
  const glm::ivec3 n0 = cellTypes.size();
  if (n0.x < 1 || n0.y < 1 || n0.z < 1)
    throw std::invalid_argument("pressure solver: cell types grid must have at least 1 cell");
  if (m.size != n0) m.d.clear();  // its ghost cells must be 0
  m.size = n0;
  m.singular = std::none_of(boundaries.begin(), boundaries.end(),
                            [](Boundary b) { return b == Boundary::Open; });

  // Level sizes: ceil(n/2) per axis. After 15 halvings the coarsest level is tiny for any grid
  // that fits in memory, so its factorization is always affordable.
  std::vector<glm::ivec3> sizes{n0};
  while (int(sizes.size()) < kMaxLevels) {
    const glm::ivec3 s = sizes.back();
    const glm::ivec3 c = (s + 1) / 2;
    if (c == s) break;  // 1 x 1 x 1
    const int lo = std::min(c.x, std::min(c.y, c.z));
    if (lo < kMinCoarseCells && BandSolver::cost(s) <= kMaxBandFlops) break;
    sizes.push_back(c);
  }
  // Buffers keep their storage when the sizes do not change (moving obstacles); ghost cells
  // are never written, so they stay 0.
  m.levels.resize(sizes.size());
  auto fit = [](auto& v, std::size_t count) {
    if (v.size() == count) return;
    v.clear();
    reserveHugePages(v, count);
    v.assign(count, 0);
  };
  for (std::size_t l = 0; l < sizes.size(); ++l) {
    Level& L = m.levels[l];
    if (L.n != sizes[l]) L = Level{};
    L.n = sizes[l];
    L.sy = L.n.x + 2;
    L.sz = std::ptrdiff_t(L.n.x + 2) * (L.n.y + 2);
    for (auto* v : {&L.diag, &L.wInv, &L.b, &L.x, &L.t}) fit(*v, L.padded());
    if (l + 1 < sizes.size()) fit(L.rows, std::size_t(sizes[l + 1].z) * (L.n.x + 2));
  }
  fit(m.d, m.levels[0].padded());
  fit(m.pd, cellTypes.count());
  fit(m.rowsD, std::size_t(n0.x) * n0.z);
  fit(m.zeroRow, std::size_t(n0.x));
  m.partial.assign(std::size_t(n0.z) * 4, 0.0);

  // Level 0's fluid mask (1/0, in diag for now); then per level: the count of fluid and air
  // neighbours (in wInv), diag = that count on fluid cells, wInv = ω / diag, and the next
  // level's mask: a coarse cell is fluid if any of its children is.
  forRows(n0, [&](int j, int k) {
    const std::uint8_t* t = &cellTypes(0, j, k);
    float* f = m.levels[0].diag.data() + m.levels[0].at(0, j, k);
    for (int i = 0; i < n0.x; ++i) f[i] = t[i] == kFluid ? 1.f : 0.f;
  });
  auto open = [&](int side) { return boundaries[side] == Boundary::Open ? 1.f : 0.f; };
  for (std::size_t l = 0; l < sizes.size(); ++l) {
    Level& L = m.levels[l];
    const std::ptrdiff_t sy = L.sy, sz = L.sz;
    const int nx = L.n.x;
    forRows(L.n, [&](int j, int k) {
      const std::size_t o = L.at(0, j, k);
      const float* __restrict f = L.diag.data() + o;
      float* __restrict c = L.wInv.data() + o;
      const float air = (j == 0 ? open(kNegY) : 0.f) + (j + 1 == L.n.y ? open(kPosY) : 0.f) +
                        (k == 0 ? open(kNegZ) : 0.f) + (k + 1 == L.n.z ? open(kPosZ) : 0.f);
      for (int i = 0; i < nx; ++i) c[i] = PLUME_NEIGHBOURS(f, i) + air;
      c[0] += open(kNegX);
      c[nx - 1] += open(kPosX);
    });
    // A fluid cell with neither fluid nor air neighbours is decoupled: treated as solid.
    forRows(L.n, [&](int j, int k) {
      float* __restrict f = L.diag.data() + L.at(0, j, k);
      float* __restrict c = L.wInv.data() + L.at(0, j, k);
      for (int i = 0; i < nx; ++i) {
        f[i] = keepIf(f[i], c[i]);
        c[i] = keepIf(f[i], kOmega / f[i]);
      }
    });
    if (l + 1 == sizes.size()) break;
    Level& C = m.levels[l + 1];
    forRows(C.n, [&](int jc, int kc) {
      float* mask = C.diag.data() + C.at(0, jc, kc);
      std::fill_n(mask, C.n.x, 0.f);
      for (int k = 2 * kc; k < std::min(2 * kc + 2, L.n.z); ++k)
        for (int j = 2 * jc; j < std::min(2 * jc + 2, L.n.y); ++j) {
          const float* f = L.diag.data() + L.at(0, j, k);
          for (int i = 0; i < nx; ++i)
            if (f[i] > 0.f) mask[i >> 1] = 1.f;
        }
    });
  }
  const auto& diag0 = m.levels[0].diag;
  m.fluidCount = double(std::count_if(diag0.begin(), diag0.end(), [](float v) { return v > 0.f; }));
  m.band.build(m.levels.back());
}

void PressureSolver::applyOperator(const ScalarGrid& x, ScalarGrid& y) const {
  const Impl& m = *mImpl;
  if (m.levels.empty())
    throw std::invalid_argument("pressure solver: setup() must be called first");
  if (x.size() != m.size) throw std::invalid_argument("pressure solver: x size must match setup()");
  if (y.size() != m.size) y.resize(m.size);
  forRows(m.size, [&](int j, int k) { m.applyRow<float>(x.data(), j, k, &y(0, j, k)); });
}

PressureStats PressureSolver::solve(const ScalarGrid& rhs, ScalarGrid& pressure, float tolerance,
                                    int maxIterations) {
  Impl& m = *mImpl;
  if (m.levels.empty())
    throw std::invalid_argument("pressure solver: setup() must be called first");
  if (rhs.size() != m.size || pressure.size() != m.size) {
    std::ostringstream s;
    s << "pressure solver: rhs and pressure must be " << m.size.x << "x" << m.size.y << "x"
      << m.size.z << " like the cell types given to setup()";
    throw std::invalid_argument(s.str());
  }
  float* p = pressure.data();
  const float* b = rhs.data();
  // Singular case: b is projected onto the range of A, i.e. made mean-free over the fluid
  // cells. This assumes the fluid cells form one connected component, so that the null space
  // of A is the constant on the fluid cells; p is returned mean-free too.
  const float meanB = m.singular ? m.fluidMean(b) : 0.f;
  PressureStats stats;
  double last = 0.0;
  for (int restart = 0;; ++restart) {
    double bb = 0.0, pp = 0.0;
    const double rr = m.residual(b, meanB, p, m.singular ? m.fluidMean(p) : 0.f, bb, pp);
    if (bb == 0.0) {
      pressure.fill(0.f);
      return PressureStats{};
    }
    const double rel = std::sqrt(rr / bb);
    stats.relativeResidual = float(rel);
    // CG stops on its recurrence residual, which drifts from the true one by round-off.
    // Restart from the true residual while that gains, but not below the round-off floor of a
    // float p (kRoundOffFloor |p|/|b|), which no float p can beat by much.
    if (rel <= tolerance || stats.iterations >= maxIterations) break;
    if (restart > 0 &&
        (restart > kMaxRestarts || rel <= kRoundOffFloor * std::sqrt(pp / bb) || rel > 0.5 * last))
      break;
    last = rel;
    m.conjugateGradients(p, rr, double(tolerance) * tolerance * bb, maxIterations, stats);
  }
  return stats;
}

}  // namespace plume
