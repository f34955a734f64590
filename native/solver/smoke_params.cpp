#include "solver/smoke_params.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace plume {
namespace {

void fail(const std::string& name, const std::string& range, double value) {
  std::ostringstream s;
  s << name << " must be " << range << " (got " << value << ")";
  throw std::invalid_argument(s.str());
}

void checkFinite(const std::string& name, double v) {
  if (!std::isfinite(v)) fail(name, "a finite number", v);
}

std::string rangeText(const SettingRange& r, const char* unit = "") {
  std::ostringstream s;
  s << "in [" << r.lo << ", " << r.hi << "]" << unit;
  return s.str();
}

void checkRange(const std::string& name, double v) {
  checkFinite(name, v);
  const SettingRange& r = smokeSettingRange(name);
  if (v < r.lo || v > r.hi) fail(name, rangeText(r), v);
}

void checkCount(const std::string& name, int v, const char* unit = "") {
  const SettingRange& r = smokeSettingRange(name);
  if (v < r.lo || v > r.hi) fail(name, rangeText(r, unit), v);
}

void checkVec(const std::string& name, glm::vec3 v) {
  for (int a = 0; a < 3; ++a) checkFinite(name, v[a]);
}

}  // namespace

const std::vector<SettingRange>& smokeSettingRanges() {
  static const std::vector<SettingRange> ranges = {
      {"resolution", 2, 1024},  // cells per axis
      {"cell_size", 1e-6, 1e6},
      {"frame_dt", 1e-6, 10.0},
      {"substeps", 1, 1000},
      {"cfl", 0.1, 100.0},
      {"alpha", -1e4, 1e4},
      {"beta", -1e4, 1e4},
      {"ambient_temperature", -1e6, 1e6},
      {"wind_strength", 0.0, 1e4},
      {"vorticity", 0.0, 1e3},
      {"density_dissipation", 0.0, 1e3},
      {"turbulence", 0.0, 1e3},
      {"turbulence_scale", 1e-4, 1e3},
      {"turbulence_rate", 0.0, 1e3},
      {"pressure_tolerance", 1e-8, 0.5},
      {"max_pressure_iterations", 1, 100000},
      {"burn_rate", 0.0, 1e4},
      {"soot_yield", 0.0, 1e4},
      {"heat_yield", 0.0, 1e4},
      {"conductivity", 0.0, 1e4},
      {"cooling_rate", 0.0, 1e6},
      {"expansion", 0.0, 1e4},
      {"flame_vorticity", 0.0, 1e3},
      {"threads", 0, 1024},  // 0 = all cores
      {"adaptive_margin", 0, 64},  // cells
      {"adaptive_threshold", 1e-6, 1.0},
  };
  return ranges;
}

const SettingRange& smokeSettingRange(const std::string& name) {
  for (const SettingRange& r : smokeSettingRanges())
    if (name == r.name) return r;
  throw std::out_of_range("SmokeParams has no range for '" + name + "'");
}

void SmokeParams::validate() const {
  for (int a = 0; a < 3; ++a) checkCount("resolution", resolution[a], " cells per axis");
  const double cells = double(resolution.x) * resolution.y * resolution.z;
  if (cells > kMaxCells) {
    std::ostringstream s;
    s << "resolution gives " << cells << " cells; at most " << kMaxCells
      << " fit in memory (about 64 bytes per cell)";
    throw std::invalid_argument(s.str());
  }
  checkRange("cell_size", cellSize);
  checkVec("origin", origin);
  checkRange("frame_dt", frameDt);
  checkCount("substeps", substeps);
  checkRange("cfl", cfl);
  checkVec("gravity", gravity);
  checkRange("alpha", alpha);
  checkRange("beta", beta);
  checkRange("ambient_temperature", ambientTemperature);
  checkVec("wind", wind);
  checkRange("wind_strength", windStrength);
  checkRange("vorticity", vorticity);
  checkRange("density_dissipation", densityDissipation);
  checkRange("turbulence", turbulence);
  checkRange("turbulence_scale", turbulenceScale);
  checkRange("turbulence_rate", turbulenceRate);
  checkRange("pressure_tolerance", pressureTolerance);
  checkCount("max_pressure_iterations", maxPressureIterations);
  checkRange("burn_rate", burnRate);
  checkRange("soot_yield", sootYield);
  checkRange("heat_yield", heatYield);
  checkRange("conductivity", conductivity);
  checkRange("cooling_rate", coolingRate);
  checkFinite("max_temperature", maxTemperature);
  if (combustion && !(maxTemperature > ambientTemperature))
    fail("max_temperature", "greater than ambient_temperature", maxTemperature);
  checkRange("expansion", expansion);
  checkRange("flame_vorticity", flameVorticity);
  checkCount("threads", threads, " (0 = all cores)");
  checkCount("adaptive_margin", adaptiveMargin, " cells");
  checkRange("adaptive_threshold", adaptiveThreshold);
}

}  // namespace plume
