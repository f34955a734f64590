#pragma once
/// \file pathline_integrator.h
/// Pathlines p(x0, t0, t) = x0 + ∫ u(p(τ), τ) dτ ([Graph Fire Synthesis] §4.2, eq. 6)
/// integrated with RK4 through one solver substep. Plume's solver holds the velocity only at
/// the start and the end of a substep, so u(x, t) inside [t0, t0 + dt] is the linear
/// interpolation in time of the two fields, each read trilinearly per MAC component.

#include "core/mac_grid3.h"

#include <glm/glm.hpp>

namespace plume {

/// The velocity of one substep: u(x, t0 + θ dt) = (1 - θ) u_start(x) + θ u_end(x).
class SubstepVelocity {
 public:
  /// `start`/`end`: face velocities (m/s) at the substep's start and end, on the grid of cell
  /// size `cellSize` whose minimum corner is `origin`. Both must have the same cells.
  SubstepVelocity(const MacGrid3& start, const MacGrid3& end, float cellSize, glm::vec3 origin)
      : mStart(start), mEnd(end), mInvCellSize(1.f / cellSize), mOrigin(origin) {}

  /// u at world position x (m) and substep fraction θ in [0, 1], m/s. Positions outside the
  /// grid read the nearest face values (clamped, as every sampler of Plume).
  glm::vec3 at(glm::vec3 x, float theta) const;

 private:
  const MacGrid3& mStart;
  const MacGrid3& mEnd;
  float mInvCellSize;
  glm::vec3 mOrigin;
};

/// Most RK4 steps one pathline takes through one substep interval.
constexpr int kMaxRk4Steps = 8;

/// Eq. 6 with the classical fourth-order Runge-Kutta method from θ = thetaA to thetaB of a
/// substep of `dt` seconds, in `steps` equal steps. `k1`, when given, is u(x, thetaA) already
/// evaluated (it is the first stage). Returns the end position.
glm::vec3 integrateRk4(const SubstepVelocity& u, glm::vec3 x, float thetaA, float thetaB,
                       float dt, int steps, const glm::vec3* k1 = nullptr);

/// integrateRk4() with as many steps as keep a particle within about one cell per step:
/// ceil(|u(x, thetaA)| (thetaB - thetaA) dt / cellSize), in [1, kMaxRk4Steps] (the solver's
/// own substeps may move four cells). The count depends on the particle only: deterministic.
glm::vec3 advancePathline(const SubstepVelocity& u, glm::vec3 x, float thetaA, float thetaB,
                          float dt, float cellSize);

}  // namespace plume
