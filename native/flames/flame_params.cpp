/// \file flame_params.cpp
/// Checks of the flame structure settings (§4.1–4.3) and of flame sources (§4.2, §6.2).

#include "flames/flame_params.h"

#include "core/format.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

std::string number(double v) { return formatNumber(v); }

/// Throws "<name> must be in [lo, hi]<unit> (got v)" unless lo <= v <= hi (NaN fails).
void requireIn(const std::string& name, double v, double lo, double hi, const char* unit) {
  if (!(v >= lo && v <= hi))
    throw std::invalid_argument(name + " must be in [" + number(lo) + ", " + number(hi) + "]" + unit +
                                " (got " + number(v) + ")");
}

/// Throws "<name> must be in (0, hi]<unit> (got v)" unless 0 < v <= hi.
void requirePositive(const std::string& name, double v, double hi, const char* unit) {
  if (!(v > 0.0 && v <= hi))
    throw std::invalid_argument(name + " must be in (0, " + number(hi) + "]" + unit + " (got " +
                                number(v) + ")");
}

void requireFinite(const std::string& name, glm::dvec3 v) {
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
    throw std::invalid_argument(name + " must be finite");
}

}  // namespace

void FlameParams::validate() const {
  if (points < kMinSpinePoints || points > kMaxSpinePoints)
    throw std::invalid_argument("points (n) must be in [" + std::to_string(kMinSpinePoints) + ", " +
                                std::to_string(kMaxSpinePoints) + "] (got " + std::to_string(points) + ")");
  requirePositive("height_intermittent (H_i)", heightIntermittent, 1000.0, " m");
  if (!(heightPersistent >= 0.0 && heightPersistent < heightIntermittent))
    throw std::invalid_argument("height_persistent (H_p) must be in [0, H_i) = [0, " +
                                number(heightIntermittent) + ") m (got " + number(heightPersistent) + ")");
  requireIn("height_max (H_max)", heightMax, heightIntermittent, 1000.0, " m (at least H_i)");
  // A: "from 1/24th second for small flames up to 2 seconds for a large pool fire" (§4.3).
  requireIn("lifespan_scale (A)", lifespanScale, 1.0 / 24.0, 2.0, " s");
  requireIn("breakaway_frequency (f)", breakawayFrequency, 0.0, 1000.0, " Hz (0 = automatic)");
  requireIn("buoyancy (beta)", buoyancy, 0.0, 100.0, "");
  requireIn("ambient_temperature (T_0)", ambientTemperature, -10.0, 10.0, "");
  requireIn("diffusion", diffusion, 0.0, 10.0, " m^2/s");
  requireFinite("gravity", gravity);
  requireIn("|gravity|", glm::length(gravity), 0.01, 1000.0, " m/s^2");
  requireIn("obstacle_margin", obstacleMargin, 0.0, 1.0, " m");
  spineNoise.validate();
}

double FlameParams::frequency(double radius) const {
  if (breakawayFrequency > 0.0) return breakawayFrequency;
  return 0.50 * std::sqrt(glm::length(gravity) / (2.0 * radius));
}

void FlameSource::validate(int index) const {
  const std::string p = "sources[" + std::to_string(index) + "].";
  requireFinite(p + "position", position);
  requireFinite(p + "velocity", velocity);
  requireFinite(p + "normal", normal);
  if (!(glm::length(normal) > 1e-12)) throw std::invalid_argument(p + "normal must not be zero");
  requirePositive(p + "radius", radius, 100.0, " m");
  if (std::isnan(startTime) || std::isinf(startTime))
    throw std::invalid_argument(p + "start_time must be finite (got " + number(startTime) + ")");
  if (!(endTime > startTime))
    throw std::invalid_argument(p + "end_time must be > start_time = " + number(startTime) + " s (got " +
                                number(endTime) + ")");
  requireIn(p + "intensity", intensity, 0.0, 1000.0, "");
  requirePositive(p + "diameter_scale", diameterScale, 100.0, "");
  requirePositive(p + "height_scale", heightScale, 100.0, "");
  requireIn(p + "temperature", temperature, 0.0, 100.0, "");
  requirePositive(p + "brightness", brightness, 1099511627776.0, "");
}

}  // namespace plume
