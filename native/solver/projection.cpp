// SmokeSolver's projection stage: boundary velocities, divergence, the MGPCG pressure solve and
// the pressure-gradient update (Stam 1999 §3; fire paper eq. 1 with its divergence φ).

#include "core/parallel.h"
#include "solver/smoke_solver.h"

#include <cmath>

namespace plume {

float SmokeSolver::fluxSum(int i, int j, int k) const {
  // Δx div u: net outflow through the six faces of cell (i,j,k).
  const MacGrid3& u = mVelocity;
  return u.u()(i + 1, j, k) - u.u()(i, j, k) + u.v()(i, j + 1, k) - u.v()(i, j, k) +
         u.w()(i, j, k + 1) - u.w()(i, j, k);
}

void SmokeSolver::enforceBoundaryVelocities() {
  const glm::ivec3 n = mParams.resolution;
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
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const std::size_t c = mRhs.index(i, j, k);
        if (mCellTypes[c] != kFluid) {
          mRhs[c] = 0.f;
          continue;
        }
        const float target = burning ? h * mDivergenceTarget[c] : 0.f;
        mRhs[c] = target - fluxSum(i, j, k);
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
