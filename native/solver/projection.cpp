// SmokeSolver's projection stage: boundary velocities, divergence, the MGPCG pressure solve and
// the pressure-gradient update (Stam 1999 §3; fire paper eq. 1 with its divergence φ).

#include "core/parallel.h"
#include "solver/smoke_solver.h"

#include <cmath>

namespace plume {
namespace {

/// Calls body(f) for the linear index f of every face of a face grid of size fs whose index
/// along axis a is `layer` (the faces of one side of the domain), slices in parallel.
template <typename Body>
void forEachFaceOfLayer(glm::ivec3 fs, int a, int layer, const Body& body) {
  const int b = (a + 1) % 3, c = (a + 2) % 3;
  parallelFor(0, fs[c], [&](int y) {
    for (int x = 0; x < fs[b]; ++x) {
      glm::ivec3 f;
      f[a] = layer;
      f[b] = x;
      f[c] = y;
      body(std::size_t(f.x) + std::size_t(fs.x) * (std::size_t(f.y) + std::size_t(fs.y) * f.z));
    }
  });
}

/// (i, j, k) of linear index f in a grid of size fs.
inline glm::ivec3 faceCoords(glm::ivec3 fs, std::size_t f) {
  const std::size_t nx = std::size_t(fs.x), ny = std::size_t(fs.y);
  return {int(f % nx), int((f / nx) % ny), int(f / (nx * ny))};
}

}  // namespace

float SmokeSolver::fluxSum(int i, int j, int k) const {
  // Δx div u: net outflow through the six faces of cell (i,j,k).
  const MacGrid3& u = mVelocity;
  return u.u()(i + 1, j, k) - u.u()(i, j, k) + u.v()(i, j + 1, k) - u.v()(i, j, k) +
         u.w()(i, j, k + 1) - u.w()(i, j, k);
}

void SmokeSolver::enforceBoundaryVelocities() {
  const glm::ivec3 n = mParams.resolution;
  if (!mHasSolids) {
    // No obstacle: only the faces on closed sides change (to 0), the rest stays as it is.
    for (int a = 0; a < 3; ++a) {
      ScalarGrid& comp = mVelocity.component(a);
      const glm::ivec3 fs = comp.size();
      for (int side = 0; side < 2; ++side) {
        if (mParams.boundaries[2 * a + side] != Boundary::Closed) continue;
        const int layer = side == 0 ? 0 : n[a];
        forEachFaceOfLayer(fs, a, layer, [&](std::size_t f) { comp[f] = 0.f; });
      }
    }
    return;
  }
  const bool noSlip = [&] {
    for (const Obstacle& o : mObstacles)
      if (o.slip == Slip::NoSlip) return true;
    return false;
  }();
  for (int a = 0; a < 3; ++a) {
    ScalarGrid& comp = mVelocity.component(a);
    const glm::ivec3 fs = comp.size();
    const bool closedLo = mParams.boundaries[2 * a] == Boundary::Closed;
    const bool closedHi = mParams.boundaries[2 * a + 1] == Boundary::Closed;
    parallelFor(0, fs.z, [&](int k) {
      for (int j = 0; j < fs.y; ++j)
        for (int i = 0; i < fs.x; ++i) {
          glm::ivec3 hi(i, j, k), lo(i, j, k);
          lo[a] -= 1;
          const bool loIn = lo[a] >= 0, hiIn = hi[a] < n[a];
          if ((!loIn && closedLo) || (!hiIn && closedHi)) {
            comp(i, j, k) = 0.f;  // a wall: no flow through the side
            continue;
          }
          const bool loSolid = loIn && mCellTypes(lo.x, lo.y, lo.z) != kFluid;
          const bool hiSolid = hiIn && mCellTypes(hi.x, hi.y, hi.z) != kFluid;
          if (loSolid || hiSolid) {
            // The normal velocity of a face touching an obstacle is the obstacle's.
            float sum = 0.f;
            int count = 0;
            if (loSolid) sum += mSolidVelocity(lo.x, lo.y, lo.z)[a], ++count;
            if (hiSolid) sum += mSolidVelocity(hi.x, hi.y, hi.z)[a], ++count;
            comp(i, j, k) = sum / float(count);
            continue;
          }
          if (!noSlip || !loIn || !hiIn) continue;
          // No-slip: a fluid face next to a no-slip obstacle (across a tangential direction)
          // takes the obstacle's velocity, so the air sticks to it.
          float sum = 0.f;
          int count = 0;
          for (int b = 0; b < 3; ++b) {
            if (b == a) continue;
            for (int d = -1; d <= 1; d += 2)
              for (const glm::ivec3& c : {lo, hi}) {
                glm::ivec3 q = c;
                q[b] += d;
                if (q[b] < 0 || q[b] >= n[b]) continue;
                const std::size_t m = mCellTypes.index(q.x, q.y, q.z);
                if (mCellTypes[m] != kFluid && mNoSlip[m]) sum += mSolidVelocity[m][a], ++count;
              }
          }
          if (count > 0) comp(i, j, k) = sum / float(count);
        }
    });
  }
}

void SmokeSolver::applyPressureGradient() {
  // u -= Δt/(ρ Δx) ∇p; the solve works with p̂ = p Δt/(ρ Δx) in velocity units. Air beyond an
  // open side has p̂ = 0; faces on walls or obstacles keep their prescribed velocity.
  const glm::ivec3 n = mParams.resolution;
  if (!mHasSolids) {
    // No obstacle: every interior face takes pHi - pLo, row by row (vectorized); the faces of
    // open sides take p̂ inside against 0 outside. The same subtractions as below.
    const std::ptrdiff_t strides[3] = {1, mPressure.strideY(), mPressure.strideZ()};
    for (int a = 0; a < 3; ++a) {
      ScalarGrid& comp = mVelocity.component(a);
      const glm::ivec3 fs = comp.size();
      const std::ptrdiff_t s = strides[a];
      parallelFor(0, fs.z, [&](int k) {
        for (int j = 0; j < fs.y; ++j) {
          // Cells (i, j, k) of the row; face (i, j, k) lies between cell (i,j,k) - e_a and it.
          float* __restrict u = &comp(0, j, k);
          const glm::ivec3 c(0, j, k);
          if (a == 0) {
            const float* __restrict p = &mPressure(0, j, k);
            for (int i = 1; i < n.x; ++i) u[i] -= p[i] - p[i - 1];
            continue;
          }
          if (c[a] == 0 || c[a] == n[a]) continue;  // the sides, below
          const float* __restrict hi = &mPressure(0, j, k);
          const float* __restrict lo = hi - s;
          for (int i = 0; i < fs.x; ++i) u[i] -= hi[i] - lo[i];
        }
      });
      for (int side = 0; side < 2; ++side) {
        if (mParams.boundaries[2 * a + side] != Boundary::Open) continue;
        const int layer = side == 0 ? 0 : n[a];
        forEachFaceOfLayer(fs, a, layer, [&](std::size_t f) {
          // The cell inside: face f itself on the low side, f - e_a (in cell indices) on the high.
          glm::ivec3 cell = faceCoords(fs, f);
          if (side == 1) cell[a] -= 1;
          const float pIn = mPressure(cell.x, cell.y, cell.z);
          comp[f] -= side == 0 ? pIn - 0.f : 0.f - pIn;
        });
      }
    }
    return;
  }
  for (int a = 0; a < 3; ++a) {
    ScalarGrid& comp = mVelocity.component(a);
    const glm::ivec3 fs = comp.size();
    const bool openLo = mParams.boundaries[2 * a] == Boundary::Open;
    const bool openHi = mParams.boundaries[2 * a + 1] == Boundary::Open;
    parallelFor(0, fs.z, [&](int k) {
      for (int j = 0; j < fs.y; ++j)
        for (int i = 0; i < fs.x; ++i) {
          glm::ivec3 hi(i, j, k), lo(i, j, k);
          lo[a] -= 1;
          const bool loIn = lo[a] >= 0, hiIn = hi[a] < n[a];
          if ((!loIn && !openLo) || (!hiIn && !openHi)) continue;
          if (loIn && mCellTypes(lo.x, lo.y, lo.z) != kFluid) continue;
          if (hiIn && mCellTypes(hi.x, hi.y, hi.z) != kFluid) continue;
          const float pLo = loIn ? mPressure(lo.x, lo.y, lo.z) : 0.f;
          const float pHi = hiIn ? mPressure(hi.x, hi.y, hi.z) : 0.f;
          comp(i, j, k) -= pHi - pLo;
        }
    });
  }
}

void SmokeSolver::project(float /*dt*/) {
  rebuildCellTypes();
  enforceBoundaryVelocities();
  const glm::ivec3 n = mParams.resolution;
  const float h = mParams.cellSize;
  const bool burning = mParams.combustion;
  // A p̂ = Δx φ - Δx div u*  (see PressureSolver for A).
  const MacGrid3& u = mVelocity;
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j) {
      // fluxSum() along the row, the same additions in the same order (vectorized).
      const float* __restrict ux = &u.u()(0, j, k);
      const float *__restrict vlo = &u.v()(0, j, k), *__restrict vhi = &u.v()(0, j + 1, k);
      const float *__restrict wlo = &u.w()(0, j, k), *__restrict whi = &u.w()(0, j, k + 1);
      const float* __restrict phi = &mDivergenceTarget(0, j, k);
      const std::uint8_t* __restrict type = &mCellTypes(0, j, k);
      float* __restrict rhs = &mRhs(0, j, k);
      for (int i = 0; i < n.x; ++i) {
        const float flux = ux[i + 1] - ux[i] + vhi[i] - vlo[i] + whi[i] - wlo[i];
        const float target = burning ? h * phi[i] : 0.f;
        rhs[i] = type[i] != kFluid ? 0.f : target - flux;
      }
    }
  });
  const PressureStats stats = mPressureSolver.solve(mRhs, mPressure, mParams.pressureTolerance,
                                                    mParams.maxPressureIterations);
  mStats.pressureIterations += stats.iterations;
  mStats.pressureResidual = std::max(mStats.pressureResidual, stats.relativeResidual);
  applyPressureGradient();
}

float SmokeSolver::maxSpeed() const {
  float m = 0.f;
  for (int a = 0; a < 3; ++a) {
    const ScalarGrid& comp = mVelocity.component(a);
    const glm::ivec3 fs = comp.size();
    m = std::max(m, float(parallelMax(0, fs.z, [&](int k) {
                   float s = 0.f;
                   const std::size_t slice = std::size_t(fs.x) * std::size_t(fs.y);
                   for (std::size_t c = std::size_t(k) * slice, e = c + slice; c < e; ++c)
                     s = std::max(s, std::fabs(comp[c]));
                   return double(s);
                 })));
  }
  return m;
}

float SmokeSolver::maxDivergence() const {
  const glm::ivec3 n = mParams.resolution;
  const float h = mParams.cellSize;
  const bool burning = mParams.combustion;
  const double worst = parallelMax(0, n.z, [&](int k) {
    double m = 0.0;
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const std::size_t c = mCellTypes.index(i, j, k);
        if (mCellTypes[c] != kFluid) continue;
        const float target = burning ? h * mDivergenceTarget[c] : 0.f;
        m = std::max(m, double(std::fabs(fluxSum(i, j, k) - target)));
      }
    return m;
  });
  const float speed = maxSpeed();
  return speed > 0.f ? float(worst / speed) : 0.f;
}

}  // namespace plume
