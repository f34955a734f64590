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

void checkRange(const std::string& name, double v, double lo, double hi) {
  checkFinite(name, v);
  if (v < lo || v > hi) {
    std::ostringstream r;
    r << "in [" << lo << ", " << hi << "]";
    fail(name, r.str(), v);
  }
}

void checkVec(const std::string& name, glm::vec3 v) {
  for (int a = 0; a < 3; ++a) checkFinite(name, v[a]);
}

}  // namespace

void SmokeParams::validate() const {
  for (int a = 0; a < 3; ++a)
    if (resolution[a] < 2 || resolution[a] > 1024) fail("resolution", "in [2, 1024] cells per axis", resolution[a]);
  const double cells = double(resolution.x) * resolution.y * resolution.z;
  if (cells > kMaxCells) {
    std::ostringstream s;
    s << "resolution gives " << cells << " cells; at most " << kMaxCells
      << " fit in memory (about 64 bytes per cell)";
    throw std::invalid_argument(s.str());
  }
  checkRange("cell_size", cellSize, 1e-6, 1e6);
  checkVec("origin", origin);
  checkRange("frame_dt", frameDt, 1e-6, 10.0);
  if (substeps < 1 || substeps > 1000) fail("substeps", "in [1, 1000]", substeps);
  checkRange("cfl", cfl, 0.1, 100.0);
  checkVec("gravity", gravity);
  checkRange("alpha", alpha, -1e4, 1e4);
  checkRange("beta", beta, -1e4, 1e4);
  checkRange("ambient_temperature", ambientTemperature, -1e6, 1e6);
  checkVec("wind", wind);
  checkRange("wind_strength", windStrength, 0.0, 1e4);
  checkRange("vorticity", vorticity, 0.0, 1e3);
  checkRange("density_dissipation", densityDissipation, 0.0, 1e3);
  checkRange("pressure_tolerance", pressureTolerance, 1e-8, 0.5);
  if (maxPressureIterations < 1 || maxPressureIterations > 100000)
    fail("max_pressure_iterations", "in [1, 100000]", maxPressureIterations);
  checkRange("burn_rate", burnRate, 0.0, 1e4);
  checkRange("soot_yield", sootYield, 0.0, 1e4);
  checkRange("heat_yield", heatYield, 0.0, 1e4);
  checkRange("conductivity", conductivity, 0.0, 1e4);
  checkRange("cooling_rate", coolingRate, 0.0, 1e6);
  checkFinite("max_temperature", maxTemperature);
  if (combustion && !(maxTemperature > ambientTemperature))
    fail("max_temperature", "greater than ambient_temperature", maxTemperature);
  checkRange("expansion", expansion, 0.0, 1e4);
  if (threads < 0 || threads > 1024) fail("threads", "in [0, 1024] (0 = all cores)", threads);
}

}  // namespace plume
