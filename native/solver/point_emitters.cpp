#include "solver/point_emitters.h"

#include "solver/pressure.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

void checkFinite(const char* name, float v) {
  if (!std::isfinite(v))
    throw std::invalid_argument(std::string("point emitter: ") + name +
                                " must be a finite number (got " + std::to_string(v) + ")");
}

}  // namespace

void PointEmitter::validate() const {
  for (int a = 0; a < 3; ++a) {
    checkFinite("position", position[a]);
    checkFinite("velocity", velocity[a]);
  }
  checkFinite("radius", radius);
  checkFinite("density_rate", densityRate);
  checkFinite("temperature", temperature);
  if (radius < 0.f)
    throw std::invalid_argument("point emitter: radius must be >= 0 m (got " +
                                std::to_string(radius) + ")");
  if (densityRate < 0.f)
    throw std::invalid_argument("point emitter: density_rate must be >= 0 (got " +
                                std::to_string(densityRate) + ")");
}

std::vector<PointEmitter> pointEmittersFrom(std::size_t count, const float* positions,
                                            const float* radii, const float* densityRates,
                                            const float* velocities, const float* temperatures) {
  std::vector<PointEmitter> emitters(count);
  for (std::size_t n = 0; n < count; ++n) {
    PointEmitter& e = emitters[n];
    for (int a = 0; a < 3; ++a) {
      e.position[a] = positions[3 * n + std::size_t(a)];
      e.velocity[a] = velocities[3 * n + std::size_t(a)];
    }
    e.radius = radii[n];
    e.densityRate = densityRates[n];
    e.temperature = temperatures[n];
  }
  return emitters;
}

void emitPoints(const std::vector<PointEmitter>& emitters, const GridFrame& grid,
                float ambientTemperature, const FlagGrid* cellTypes, float dt,
                ScalarGrid& density, ScalarGrid& temperature, MacGrid3& velocity) {
  const float h = grid.cellSize;
  const glm::ivec3 n = grid.resolution;
  const float cellVolume = h * h * h;
  for (const PointEmitter& e : emitters) {
    const float radius = std::max(e.radius, h);
    // Position in cell units, cell centres at integer + 0.5.
    const glm::vec3 p = (e.position - grid.origin) / h;
    const float rc = radius / h;
    const glm::ivec3 lo(glm::floor(p - rc - 0.5f)), hi(glm::ceil(p + rc - 0.5f));
    if (glm::any(glm::greaterThan(lo, n - 1)) || glm::any(glm::lessThan(hi, glm::ivec3(0))))
      continue;  // the whole sphere is outside the domain
    // Σ w over the sphere's whole lattice, inside the domain or not: the normalization.
    double total = 0.0;
    for (int k = lo.z; k <= hi.z; ++k)
      for (int j = lo.y; j <= hi.y; ++j)
        for (int i = lo.x; i <= hi.x; ++i) {
          const glm::vec3 d = glm::vec3(i, j, k) + 0.5f - p;
          total += std::max(0.f, 1.f - glm::dot(d, d) / (rc * rc));
        }
    if (total <= 0.0) continue;  // cannot happen for R >= Δx (the nearest centre is within √3/2)
    const double massPerWeight = double(e.densityRate) * double(dt) / total;
    const float hot = ambientTemperature + e.temperature;
    const bool moving = e.velocity != glm::vec3(0.f);
    for (int k = std::max(lo.z, 0); k <= std::min(hi.z, n.z - 1); ++k)
      for (int j = std::max(lo.y, 0); j <= std::min(hi.y, n.y - 1); ++j)
        for (int i = std::max(lo.x, 0); i <= std::min(hi.x, n.x - 1); ++i) {
          const glm::vec3 d = glm::vec3(i, j, k) + 0.5f - p;
          const float w = 1.f - glm::dot(d, d) / (rc * rc);
          if (w <= 0.f) continue;
          const std::size_t c = density.index(i, j, k);
          if (cellTypes && (*cellTypes)[c] != kFluid) continue;
          density[c] += float(massPerWeight * w / cellVolume);
          if (e.temperature != 0.f) temperature[c] = std::max(temperature[c], hot);
          if (!moving) continue;  // a still emitter leaves the flow alone, like a still Source
          velocity.u()(i, j, k) = velocity.u()(i + 1, j, k) = e.velocity.x;
          velocity.v()(i, j, k) = velocity.v()(i, j + 1, k) = e.velocity.y;
          velocity.w()(i, j, k) = velocity.w()(i, j, k + 1) = e.velocity.z;
        }
  }
}

}  // namespace plume
