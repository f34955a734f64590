/// \file incandescence.cpp
/// Eq. 5–6 and the reference-image colour lookup.

#include "flames/incandescence.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {

void ColorImage::validate() const {
  if (width < 0 || height < 0 || rgb.size() != std::size_t(width) * std::size_t(height) * 3)
    throw std::invalid_argument("color image must hold width x height x 3 floats (got " + std::to_string(rgb.size()) +
                                " for " + std::to_string(width) + "x" + std::to_string(height) + ")");
  for (float v : rgb)
    if (!std::isfinite(v)) throw std::invalid_argument("color image values must be finite");
}

glm::vec3 ColorImage::sample(double u, double v) const {
  if (width == 0 || height == 0) return glm::vec3(1.f);
  const double x = std::clamp(u, 0.0, 1.0) * width - 0.5, y = std::clamp(v, 0.0, 1.0) * height - 0.5;
  const int x0 = std::clamp(int(std::floor(x)), 0, width - 1), y0 = std::clamp(int(std::floor(y)), 0, height - 1);
  const int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
  const float fx = float(std::clamp(x - x0, 0.0, 1.0)), fy = float(std::clamp(y - y0, 0.0, 1.0));
  auto at = [&](int i, int j) {
    const float* p = &rgb[(std::size_t(j) * std::size_t(width) + std::size_t(i)) * 3];
    return glm::vec3(p[0], p[1], p[2]);
  };
  return glm::mix(glm::mix(at(x0, y0), at(x1, y0), fx), glm::mix(at(x0, y1), at(x1, y1), fx), fy);
}

void IncandescenceParams::validate() const {
  if (!(k >= 0.0 && std::isfinite(k))) throw std::invalid_argument("energy_scale (k) must be a finite number >= 0");
  if (!(heatOfCombustion >= 0.0 && heatOfCombustion <= 1e9))
    throw std::invalid_argument("heat_of_combustion must be in [0, 1e9] J/kg (got " + std::to_string(heatOfCombustion) + ")");
  if (!(fuelArea >= 0.0 && std::isfinite(fuelArea)))
    throw std::invalid_argument("fuel_area must be a finite number >= 0 m² (0: the source disc)");
}

double flameEnergy(const IncandescenceParams& p, double speed, double radius, double height) {
  if (!(height > 0.0) || !(radius > 0.0)) return 0.0;
  const double m = speed * radius * radius;
  const double area = p.fuelArea > 0.0 ? p.fuelArea : 3.14159265358979323846 * radius * radius;
  return 0.5 * p.k * 0.3 * m * p.heatOfCombustion * 2.0 * area * radius * radius * radius / height;
}

double incandescenceFactor(double energy, std::size_t count, double meanDensity, double height, double distance) {
  if (count == 0 || !(meanDensity > 0.0)) return 0.0;
  const double spread = 4.0 * 3.14159265358979323846 * (0.25 * height * height + distance * distance);
  return energy / (double(count) * spread * meanDensity);
}

}  // namespace plume
