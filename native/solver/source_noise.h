#pragma once
/// \file source_noise.h
/// Flicker of a fire source and Breakup of a smoke source: a smooth, animated value noise that
/// thins what a source emits (fuel; smoke and heat) in patches, so it leaves the source as
/// flickering tongues or uneven puffs rather than one even sheet. A perfectly even source over a
/// symmetric scene keeps the flow symmetric, and the flames rise as a mirrored "Christmas tree";
/// real burners are never even.
/// Mantaflow's counterpart is a Flow Source's texture; EmberGen's is its emitter noise.

#include <glm/glm.hpp>

#include <cstdint>

namespace plume {

/// The noise's settings (per source; SourceSettings::fuelNoise).
struct SourceNoise {
  float amount = 0.f;   ///< a in [0, 1]: share of the emission the noise may take away
  float scale = 0.05f;  ///< λ, metres: size of the patches
  float rate = 4.f;     ///< patches renewed per second (the flicker's speed)
};

/// Value noise in [0, 1] at world point p and time t (seconds), smooth in space and time
/// (quintic fade between lattice values, two octaves), the same for the same (p, t, settings,
/// seed) on any machine. `stream` tells sources apart.
float sourceNoiseValue(const glm::vec3& p, double t, const SourceNoise& noise, std::uint64_t seed,
                       std::uint64_t stream);

/// The factor 1 - a n(p, t) a source's fuel is multiplied by.
inline float sourceNoiseFactor(const glm::vec3& p, double t, const SourceNoise& noise,
                               std::uint64_t seed, std::uint64_t stream) {
  if (noise.amount <= 0.f) return 1.f;
  return 1.f - noise.amount * sourceNoiseValue(p, t, noise, seed, stream);
}

}  // namespace plume
