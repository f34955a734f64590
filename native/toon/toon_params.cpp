/// \file toon_params.cpp
/// ToonParams checks and ramps ([Cartoon Smoke] §2.3: "simple linear interpolation ramps").

#include "toon/toon_params.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace plume {
namespace {

std::string number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// Throws "<name> must be in [lo, hi]<unit> (got v)" unless lo <= v <= hi (NaN fails).
void requireRange(const char* name, double v, double lo, double hi, const char* unit = "") {
  if (!(v >= lo && v <= hi))
    throw std::invalid_argument(std::string(name) + " must be in [" + number(lo) + ", " +
                                number(hi) + "]" + unit + " (got " + number(v) + ")");
}

void requireFinite(const char* name, double v, const char* what) {
  if (!std::isfinite(v))
    throw std::invalid_argument(std::string(name) + " must be " + what + " (got " + number(v) + ")");
}

}  // namespace

void ToonParams::validate() const {
  requireRange("emission_count", emissionCount, 0, kMaxToonEmission, " particles per frame");
  requireFinite("death_density", deathDensity, "a finite number >= 0");
  requireRange("death_density", deathDensity, 0.0, HUGE_VAL);
  requireFinite("birth_density", birthDensity, "a finite number > death_density");
  if (!(birthDensity > deathDensity))
    throw std::invalid_argument("birth_density must be > death_density (" + number(deathDensity) +
                                ") so that a newborn particle is not dying (got " +
                                number(birthDensity) + ")");
  requireRange("birth_spacing", birthSpacing, 0.0, kMaxToonBirthSpacing,
               " stencil sizes (0 = a particle in every empty dense cell)");
  requireFinite("ramp_density_low", rampDensityLow, "finite");
  requireFinite("ramp_density_high", rampDensityHigh, "finite");
  if (!(rampDensityHigh > rampDensityLow))
    throw std::invalid_argument("ramp_density_high must be > ramp_density_low (" +
                                number(rampDensityLow) + "; got " + number(rampDensityHigh) + ")");
  requireFinite("size_low", sizeLow, "a finite number >= 0 metres");
  requireRange("size_low", sizeLow, 0.0, HUGE_VAL, " metres");
  requireFinite("size_high", sizeHigh, "a finite number >= 0 metres");
  requireRange("size_high", sizeHigh, 0.0, HUGE_VAL, " metres");
  if (!(std::max(sizeLow, sizeHigh) > 0.f))
    throw std::invalid_argument("size_low or size_high must be > 0 metres (both are 0)");
  requireRange("max_size_change", maxSizeChange, 1e-4, 1.0, " of the largest size per frame");
  requireRange("max_count", maxCount, 1, kMaxToonParticles, " particles");
  if (integration != ToonIntegration::Euler && integration != ToonIntegration::Midpoint)
    throw std::invalid_argument("integration must be EULER or MIDPOINT");
  requireRange("cfl", cfl, kMinToonCfl, kMaxToonCfl, " cells per substep");
  requireFinite("stretch_factor", stretchFactor, "a finite number >= 0 s/m");
  requireRange("stretch_factor", stretchFactor, 0.0, 1e6, " s/m");
  if (colorDriver != ToonColorDriver::Density && colorDriver != ToonColorDriver::Temperature &&
      colorDriver != ToonColorDriver::Speed)
    throw std::invalid_argument("color_driver must be DENSITY, TEMPERATURE or SPEED");
  requireFinite("color_low", colorLow, "finite");
  requireFinite("color_high", colorHigh, "finite");
  if (!(colorHigh > colorLow))
    throw std::invalid_argument("color_high must be > color_low (" + number(colorLow) +
                                "; got " + number(colorHigh) + ")");
  requireRange("threads", threads, 0, 1024, " (0 = all cores)");
}

float ToonParams::maxSizeStep() const { return maxSizeChange * std::max(sizeLow, sizeHigh); }

}  // namespace plume
