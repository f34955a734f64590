#pragma once
/// \file flame_sampler.h
/// Monte-Carlo sampling of a flame's density ([Structural Flames] §4.4, §5.3): how many
/// samples ("super-sample the profile with sufficient density for complete coverage": the
/// flame's projected area on the camera times particles per pixel, about ten in the paper, or a
/// fixed count), and the samples themselves, fresh every frame, seeded per flame and particle so
/// the result does not depend on the thread count.

#include "flames/profile_density.h"
#include "flames/spine_mapping.h"

#include <glm/glm.hpp>

#include <cstdint>

namespace plume {

/// The render camera, for the projected area (§5.3) and the distance l of eq. 6.
struct FlameCamera {
  glm::dvec3 position{0.0, -5.0, 1.0};  ///< m
  double focalLength = 50.0;            ///< mm
  double sensorWidth = 36.0;            ///< mm, across the image width
  int width = 1920, height = 1080;      ///< pixels
  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
  /// Pixels per metre at distance l (pinhole: f / sensor · width / l).
  double pixelsPerMetre(double distance) const;
};

/// How many samples a flame gets.
struct SamplingParams {
  double particlesPerPixel = 10.0;  ///< §5.3: about ten
  int minParticles = 64;            ///< per flame
  int maxParticles = 100000;        ///< per flame (the paper: 1,000 to 50,000)
  int fixedCount = 0;               ///< > 0: every flame gets exactly this many
  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
};

/// Approximate projected area (m² seen at the camera, converted to pixels) of the flame's
/// sampled shell: 16 slices along the spine, each a cylinder of radius R (r(s) + shell) seen at
/// its angle to the view direction, plus the widest cross-section seen end-on.
double projectedPixels(const ProfileDensity& density, const SpineFrame& spine, double radius,
                       const FlameCamera& camera);

/// Sample count for a flame: fixedCount, or particlesPerPixel × projectedPixels clamped to
/// [minParticles, maxParticles].
int particleCount(const SamplingParams& params, const ProfileDensity& density, const SpineFrame& spine,
                  double radius, const FlameCamera& camera);

/// Sample `index` of `count` of flame `flameId` (canonical space): stratum (index + ξ) / count,
/// random numbers from Rng(seed, flameId · 2³² + index).
ProfileSample sampleFlame(const ProfileDensity& density, std::uint64_t seed, std::uint32_t flameId, int index,
                          int count, Rng* rngOut = nullptr);

}  // namespace plume
