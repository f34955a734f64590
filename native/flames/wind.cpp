/// \file wind.cpp
/// Wind fields w(x, t) of eq. 1 (§4.2, §6).

#include "flames/wind.h"

#include "core/rng.h"
#include "core/sampling.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

bool finite(glm::dvec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void requireFiniteVector(glm::dvec3 v, const char* what) {
  if (!finite(v)) throw std::invalid_argument(std::string(what) + " must be finite");
}

/// A unit vector uniformly distributed on the sphere.
glm::dvec3 randomDirection(Rng& rng) {
  const double z = rng.uniform(-1.0, 1.0), a = 6.283185307179586 * rng.uniform();
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {r * std::cos(a), r * std::sin(a), z};
}

}  // namespace

UniformWind::UniformWind(glm::dvec3 velocity) : mVelocity(velocity) {
  requireFiniteVector(velocity, "wind velocity");
}

glm::dvec3 UniformWind::evaluate(const glm::dvec3&, double) const { return mVelocity; }

VortexWind::VortexWind(glm::dvec3 center, glm::dvec3 axis, double strength, double coreRadius)
    : mCenter(center), mStrength(strength), mCoreRadius(coreRadius) {
  requireFiniteVector(center, "vortex center");
  requireFiniteVector(axis, "vortex axis");
  if (!(glm::length(axis) > 1e-12)) throw std::invalid_argument("vortex axis must not be zero");
  if (!std::isfinite(strength)) throw std::invalid_argument("vortex strength must be finite");
  if (!(coreRadius > 0.0 && std::isfinite(coreRadius)))
    throw std::invalid_argument("vortex core_radius must be a finite number > 0 m");
  mAxis = glm::normalize(axis);
}

glm::dvec3 VortexWind::evaluate(const glm::dvec3& x, double) const {
  const glm::dvec3 d = x - mCenter;
  const glm::dvec3 radial = d - glm::dot(d, mAxis) * mAxis;
  const double r = glm::length(radial);
  if (r <= 0.0) return glm::dvec3(0.0);
  // Speed strength·r/r_c inside the core (solid body), strength outside.
  const double speed = mStrength * std::min(1.0, r / mCoreRadius);
  return speed * glm::cross(mAxis, radial / r);
}

TurbulenceWind::TurbulenceWind(double strength, double size, double flow, std::uint64_t seed, int modes) {
  if (!(strength >= 0.0 && std::isfinite(strength)))
    throw std::invalid_argument("turbulence strength must be a finite number >= 0 m/s");
  if (!(size > 0.0 && std::isfinite(size)))
    throw std::invalid_argument("turbulence size must be a finite number > 0 m");
  if (!(flow >= 0.0 && std::isfinite(flow)))
    throw std::invalid_argument("turbulence flow must be a finite number >= 0 Hz");
  if (modes < 1 || modes > 1024) throw std::invalid_argument("turbulence modes must be in [1, 1024]");
  Rng rng(seed, /*stream=*/0x7475726275ull);
  // Each mode contributes a cosine of unit amplitude (mean square ½ per mode after normalizing
  // k × a_k); the sum of `modes` independent ones has mean square modes/2, hence the scale.
  const double scale = strength * std::sqrt(2.0 / double(modes));
  for (int m = 0; m < modes; ++m) {
    Mode mode;
    // |k| spread over an octave around 2π/size.
    const double wavenumber = 6.283185307179586 / size * rng.uniform(0.7, 1.4);
    mode.k = wavenumber * randomDirection(rng);
    glm::dvec3 a = glm::cross(mode.k, randomDirection(rng));
    while (glm::length(a) < 1e-6 * wavenumber) a = glm::cross(mode.k, randomDirection(rng));
    mode.amplitude = scale * glm::normalize(a);  // already ⟂ k: the curl's direction
    mode.omega = 6.283185307179586 * flow * rng.uniform(0.5, 1.5);
    mode.phase = 6.283185307179586 * rng.uniform();
    mModes.push_back(mode);
  }
}

glm::dvec3 TurbulenceWind::evaluate(const glm::dvec3& x, double t) const {
  // w = Σ (k × a_k) cos(k·x + ω t + φ): each term is ⟂ k, so ∇·w = −Σ (k·(k × a_k)) sin(...) = 0.
  glm::dvec3 w(0.0);
  for (const Mode& m : mModes) w += m.amplitude * std::cos(glm::dot(m.k, x) + m.omega * t + m.phase);
  return w;
}

GridWind::GridWind(VectorGrid values, double cellSize, glm::dvec3 origin)
    : mField(std::move(values), float(cellSize), glm::vec3(origin)) {}

glm::dvec3 GridWind::evaluate(const glm::dvec3& x, double) const { return glm::dvec3(mField.at(glm::vec3(x))); }

MacWind::MacWind(MacGrid3 velocity, double cellSize, glm::dvec3 origin)
    : mVelocity(std::move(velocity)), mOrigin(origin) {
  const glm::ivec3 n = mVelocity.cells();
  if (n.x < 1 || n.y < 1 || n.z < 1) throw std::invalid_argument("MAC wind grid must have >= 1 cell per axis");
  if (!(cellSize > 0.0 && std::isfinite(cellSize)))
    throw std::invalid_argument("MAC wind cell_size must be a finite number > 0 m");
  requireFiniteVector(origin, "MAC wind origin");
  for (int a = 0; a < 3; ++a)
    for (std::size_t i = 0; i < mVelocity.component(a).count(); ++i)
      if (!std::isfinite(mVelocity.component(a)[i]))
        throw std::invalid_argument("MAC wind grid holds a non-finite value");
  mInvCellSize = 1.0 / cellSize;
}

glm::dvec3 MacWind::evaluate(const glm::dvec3& x, double) const {
  // sampleVelocity() takes cell coordinates with cell (i,j,k)'s centre at (i,j,k).
  const glm::dvec3 p = (x - mOrigin) * mInvCellSize - glm::dvec3(0.5);
  return glm::dvec3(sampleVelocity(mVelocity, glm::vec3(p)));
}

void CompositeWind::add(std::shared_ptr<const WindField> field) {
  if (!field) throw std::invalid_argument("wind field must not be None");
  mFields.push_back(std::move(field));
}

glm::dvec3 CompositeWind::evaluate(const glm::dvec3& x, double t) const {
  glm::dvec3 w(0.0);
  for (const auto& f : mFields) w += f->evaluate(x, t);
  return w;
}

}  // namespace plume
