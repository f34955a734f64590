/// \file evolution.cpp
/// Eq. 1 and 2 over one step for the points of one flame (§4.2).

#include "flames/evolution.h"

#include <cmath>

namespace plume {

glm::dvec3 buoyancyVelocity(const FlameParams& params, double temperature, double age) {
  const double g = glm::length(params.gravity);
  const glm::dvec3 up = -params.gravity / g;
  return params.buoyancy * g * (temperature - params.ambientTemperature) * age * up;
}

glm::dvec3 driftVelocity(const FlameParams& params, const WindField* wind, const glm::dvec3& x, double t,
                         double age, double temperature, const glm::dvec3& sourceTerm, const SpineNoise* noise) {
  glm::dvec3 v = sourceTerm + buoyancyVelocity(params, temperature, age);
  if (wind) v += wind->evaluate(x, t);
  if (noise && noise->enabled()) v += noise->velocity(x, t);
  return v;
}

void evolvePoints(std::vector<SpinePoint>& points, const FlameParams& params, const EvolutionInput& in,
                  Rng& rng) {
  const double dt = in.dt, t = in.time;
  auto f = [&](const glm::dvec3& x, double time, double age) {
    return driftVelocity(params, in.wind, x, time, age, in.temperature, in.sourceTerm, in.noise);
  };
  const double sigma = in.temperature * std::sqrt(2.0 * params.diffusion * dt);
  for (SpinePoint& p : points) {
    const glm::dvec3 x0 = p.x;
    const double a = p.age;
    glm::dvec3 x1;
    switch (params.integrator) {
      case FlameIntegrator::Euler:
        x1 = x0 + dt * f(x0, t, a);
        break;
      case FlameIntegrator::Midpoint: {
        const glm::dvec3 k1 = f(x0, t, a);
        x1 = x0 + dt * f(x0 + 0.5 * dt * k1, t + 0.5 * dt, a + 0.5 * dt);
        break;
      }
      case FlameIntegrator::RungeKutta4: {
        const glm::dvec3 k1 = f(x0, t, a);
        const glm::dvec3 k2 = f(x0 + 0.5 * dt * k1, t + 0.5 * dt, a + 0.5 * dt);
        const glm::dvec3 k3 = f(x0 + 0.5 * dt * k2, t + 0.5 * dt, a + 0.5 * dt);
        const glm::dvec3 k4 = f(x0 + dt * k3, t + dt, a + dt);
        x1 = x0 + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        break;
      }
    }
    p.v = (x1 - x0) / dt;
    if (sigma > 0.0) {
      // Named draws: C++ leaves the order of a call's arguments to the compiler (GCC took
      // these right to left, clang left to right), so the same seed gave other flames in
      // another build. z, y, x is GCC's order, which earlier bakes used.
      const double nz = rng.normal(), ny = rng.normal(), nx = rng.normal();
      x1 += sigma * glm::dvec3(nx, ny, nz);
    }
    p.x = x1;
    p.age = a + dt;
  }
}

}  // namespace plume
