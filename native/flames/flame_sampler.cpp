/// \file flame_sampler.cpp
/// Sample counts from the camera and the per-particle samples.

#include "flames/flame_sampler.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {

void FlameCamera::validate() const {
  if (!std::isfinite(position.x) || !std::isfinite(position.y) || !std::isfinite(position.z))
    throw std::invalid_argument("camera position must be finite");
  if (!(focalLength > 0.0 && focalLength <= 1e4))
    throw std::invalid_argument("camera focal_length must be in (0, 10000] mm (got " + std::to_string(focalLength) + ")");
  if (!(sensorWidth > 0.0 && sensorWidth <= 1e3))
    throw std::invalid_argument("camera sensor_width must be in (0, 1000] mm (got " + std::to_string(sensorWidth) + ")");
  if (width < 1 || height < 1 || width > 65536 || height > 65536)
    throw std::invalid_argument("camera resolution must be in [1, 65536] pixels per side");
}

double FlameCamera::pixelsPerMetre(double distance) const {
  return focalLength / sensorWidth * double(width) / std::max(distance, 1e-6);
}

void SamplingParams::validate() const {
  if (!(particlesPerPixel > 0.0 && particlesPerPixel <= 1e4))
    throw std::invalid_argument("particles_per_pixel must be in (0, 10000] (got " + std::to_string(particlesPerPixel) + ")");
  if (minParticles < 1) throw std::invalid_argument("min_particles must be >= 1");
  if (maxParticles < minParticles || maxParticles > 100000000)
    throw std::invalid_argument("max_particles must be in [min_particles, 1e8] (got " + std::to_string(maxParticles) + ")");
  if (fixedCount < 0 || fixedCount > 100000000)
    throw std::invalid_argument("fixed_count must be in [0, 1e8] (0: from the camera)");
}

double projectedPixels(const ProfileDensity& density, const SpineFrame& spine, double radius,
                       const FlameCamera& camera) {
  constexpr int kSlices = 16;
  const double aspect = density.profile().aspect();
  const double shell = density.rhoMax() - 1.0;
  const double s0 = density.zMin() / aspect, s1 = density.zMax() / aspect;
  const double ds = (s1 - s0) / kSlices;
  double pixels = 0.0, widest = 0.0, endOn = 0.0;
  for (int j = 0; j < kSlices; ++j) {
    const double s = s0 + (j + 0.5) * ds;
    glm::dvec3 c, t, n, b;
    spine.frameAt(s, &c, &t, &n, &b);
    const glm::dvec3 toFlame = c - camera.position;
    const double l = glm::length(toFlame);
    const glm::dvec3 view = l > 0.0 ? toFlame / l : glm::dvec3(0.0, 0.0, 1.0);
    const double rho = radius * (density.profile().radius(s) + shell);
    const double ppm = camera.pixelsPerMetre(l);
    pixels += 2.0 * rho * ds * spine.length() * glm::length(glm::cross(t, view)) * ppm * ppm;
    if (rho > widest) widest = rho, endOn = std::fabs(glm::dot(t, view)) * ppm * ppm;
  }
  return pixels + 3.14159265358979323846 * widest * widest * endOn;
}

int particleCount(const SamplingParams& params, const ProfileDensity& density, const SpineFrame& spine,
                  double radius, const FlameCamera& camera) {
  if (params.fixedCount > 0) return params.fixedCount;
  const double n = params.particlesPerPixel * projectedPixels(density, spine, radius, camera);
  return int(std::clamp(n, double(params.minParticles), double(params.maxParticles)));
}

ProfileSample sampleFlame(const ProfileDensity& density, std::uint64_t seed, std::uint32_t flameId, int index,
                          int count, Rng* rngOut) {
  Rng rng(seed, (std::uint64_t(flameId) << 32) | std::uint32_t(index));
  const double u = (double(index) + rng.uniform()) / double(count);
  ProfileSample s = density.sample(u, rng);
  if (rngOut) *rngOut = rng;
  return s;
}

}  // namespace plume
