#pragma once
/// \file evolution.h
/// Flame evolution ([Structural Flames] §4.2): each structural particle p moves by eq. 1,
///   dx_p/dt = w(x_p, t) + v_K(x_p, t) + d(T_p) + V_p + c(T_p, t),
/// wind, the Kolmogorov noise field ("we add rotational components in the form of simulated wind
/// fields and a noise field generated from a Kolmogorov spectrum", spine_noise.h), Brownian
/// diffusion scaled by temperature, source motion and buoyancy (eq. 2).

#include "core/rng.h"
#include "flames/flame.h"
#include "flames/flame_params.h"
#include "flames/spine_noise.h"
#include "flames/wind.h"

#include <vector>

namespace plume {

/// Eq. 2 as used here. The extracted text reads c = g_y (T_0 − T_p) t_p² with β named in the prose
/// but missing from the formula, and calls c a motion although eq. 1 sums velocities. The
/// physically sensible reading: buoyancy is "a direct linear upward force", constant over the
/// particle's life, i.e. an acceleration β |g| (T_p − T_0) upwards, whose velocity after t_p
/// seconds is c = β |g| (T_p − T_0) t_p · up (the t_p² is the displacement ½ a t_p², not a velocity).
/// With g_y < 0 this equals β g_y (T_0 − T_p) t_p, the printed sign.
glm::dvec3 buoyancyVelocity(const FlameParams& params, double temperature, double age);

/// The deterministic part of eq. 1 (no diffusion) at x, time t, particle age t_p:
/// w(x, t) + v_K(x, t) + V_p + c(T_p, t). `sourceTerm` is V_p (see EvolutionInput::sourceTerm);
/// `noise` is v_K (null: none).
glm::dvec3 driftVelocity(const FlameParams& params, const WindField* wind, const glm::dvec3& x, double t,
                         double age, double temperature, const glm::dvec3& sourceTerm,
                         const SpineNoise* noise = nullptr);

/// What a step of eq. 1 needs besides the points.
struct EvolutionInput {
  const WindField* wind = nullptr;  ///< w (null: still air)
  const SpineNoise* noise = nullptr;  ///< v_K, the Kolmogorov noise field (null: none)
  double time = 0.0;                ///< t at the start of the step (s)
  double dt = 0.0;                  ///< step (s), > 0
  double temperature = 1.0;         ///< T_p of the flame (normalized)
  /// V_p of eq. 1: −V (the source's velocity through the air, negated) for a flame attached to
  /// a moving source, whose points are kept in the source's frame (§4.2: "the flame is then
  /// generated in a stationary reference frame"); zero for separated flames, which are free.
  glm::dvec3 sourceTerm{0.0};
};

/// Advances every point by dt: the drift by the chosen integrator (the age, hence c, advancing
/// within the step), then d(T_p): Brownian motion scaled by temperature, a Gaussian displacement
/// of standard deviation T_p (2 D dt)^½ per axis (D = params.diffusion), drawn from `rng` in point
/// order. Sets each point's v to its drift over the step (no diffusion: v feeds motion blur and
/// noise propagation) and adds dt to its age.
void evolvePoints(std::vector<SpinePoint>& points, const FlameParams& params, const EvolutionInput& input,
                  Rng& rng);

}  // namespace plume
