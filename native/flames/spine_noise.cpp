/// \file spine_noise.cpp
/// The Kolmogorov velocity of eq. 1 (§4.2): the §4.5 tile read as a velocity.

#include "flames/spine_noise.h"

#include "core/format.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

void requireIn(const std::string& name, double v, double lo, double hi, const char* unit) {
  if (!(v >= lo && v <= hi))
    throw std::invalid_argument(name + " must be in [" + formatNumber(lo) + ", " + formatNumber(hi) + "]" + unit +
                                " (got " + formatNumber(v) + ")");
}

}  // namespace

void SpineNoiseParams::validate() const {
  requireIn("spine_noise_amplitude", amplitude, 0.0, kMaxSpineNoiseAmplitude, " m/s");
  if (!(scale > 0.0 && scale <= kMaxSpineNoiseScale))
    throw std::invalid_argument("spine_noise_scale (Lambda) must be in (0, " + formatNumber(kMaxSpineNoiseScale) +
                                "] m (got " + formatNumber(scale) + ")");
  requireIn("spine_noise_frequency (nu)", frequency, 0.0, kMaxSpineNoiseFrequency, " Hz");
  for (int a = 0; a < 3; ++a)
    requireIn(std::string("spine_noise_drift (c) ") + "xyz"[a], drift[a], -kMaxSpineNoiseDrift, kMaxSpineNoiseDrift,
              " m/s");
  if (resolution < 8 || resolution > 128 || (resolution & (resolution - 1)) != 0)
    throw std::invalid_argument("spine_noise_resolution must be a power of two in [8, 128] (got " +
                                std::to_string(resolution) + ")");
}

SpineNoise::SpineNoise(const SpineNoiseParams& params, std::uint64_t seed) : mParams(params) {
  params.validate();
  if (!(params.amplitude > 0.0)) return;
  KolmogorovParams field;
  field.amplitude = 1.0;  // unit RMS: velocity() scales it
  field.scale = params.scale;
  field.drift = params.drift;
  field.frequency = params.frequency;
  field.resolution = params.resolution;
  // Its own stream of the system's seed: not the render particles' field of the same seed.
  mField = std::make_shared<KolmogorovNoise>(field, seed ^ 0x5E11E5B1A0C0FFEEull);
}

SpineNoise::SpineNoise(const SpineNoiseParams& params, std::uint64_t seed, const SpineNoise& previous) {
  SpineNoiseParams same = previous.mParams;
  same.amplitude = params.amplitude;
  if (previous.mField && params.amplitude > 0.0 && same == params) {
    params.validate();
    mParams = params;
    mField = previous.mField;
  } else {
    *this = SpineNoise(params, seed);
  }
}

glm::dvec3 SpineNoise::velocity(const glm::dvec3& x, double t) const {
  if (!mField) return glm::dvec3(0.0);
  return mParams.amplitude * mField->displacement(x, t);
}

}  // namespace plume
