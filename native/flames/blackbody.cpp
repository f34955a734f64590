/// \file blackbody.cpp
/// Planck × CIE 1931 (Wyman–Sloan–Shirley fit) → XYZ → linear Rec. 709.

#include "flames/blackbody.h"

#include <algorithm>
#include <cmath>

namespace plume {
namespace {

/// The piecewise Gaussian of the fit: σ1 left of μ, σ2 right of it (λ in nm).
double lobe(double lambda, double mu, double sigma1, double sigma2) {
  const double t = (lambda - mu) / (lambda < mu ? sigma1 : sigma2);
  return std::exp(-0.5 * t * t);
}

glm::dvec3 cie1931(double l) {
  const double x = 1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) -
                   0.065 * lobe(l, 501.1, 20.4, 26.2);
  const double y = 0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1);
  const double z = 1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8);
  return {x, y, z};
}

}  // namespace

glm::vec3 blackbodyColor(double kelvin) {
  const double t = std::clamp(kelvin, 500.0, 40000.0);
  constexpr double c2 = 1.4387769e7;  // second radiation constant h c / k_B, nm·K
  glm::dvec3 xyz(0.0);
  for (double l = 380.0; l <= 780.0; l += 5.0)
    xyz += cie1931(l) * (std::pow(l, -5.0) / std::expm1(c2 / (l * t)));
  const glm::dvec3 rgb(3.2406 * xyz.x - 1.5372 * xyz.y - 0.4986 * xyz.z,
                       -0.9689 * xyz.x + 1.8758 * xyz.y + 0.0415 * xyz.z,
                       0.0557 * xyz.x - 0.2040 * xyz.y + 1.0570 * xyz.z);
  glm::vec3 c(float(std::max(rgb.x, 0.0)), float(std::max(rgb.y, 0.0)), float(std::max(rgb.z, 0.0)));
  const float y = luminance(c);
  return y > 0.f ? c / y : glm::vec3(1.f);
}

BlackbodyRamp::BlackbodyRamp(double kelvin) : mTable(256) {
  for (std::size_t k = 0; k < mTable.size(); ++k)
    mTable[k] = blackbodyColor(kelvin * double(k) / double(mTable.size() - 1));
}

glm::vec3 BlackbodyRamp::operator()(double fraction) const {
  const double x = std::clamp(fraction, 0.0, 1.0) * double(mTable.size() - 1);
  const std::size_t k = std::min(std::size_t(x), mTable.size() - 2);
  return glm::mix(mTable[k], mTable[k + 1], float(x - double(k)));
}

}  // namespace plume
