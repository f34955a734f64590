#include "nurbs/chord_parameters.h"

#include <cmath>
#include <stdexcept>

namespace plume {

std::vector<double> averagedChordParameters(const PolylineGrid& g, double exponent) {
  if (g.count < 1 || g.rows < 1 || g.points == nullptr)
    throw std::invalid_argument("chord parameters need at least one polyline of one point");
  if (!(exponent >= 0.0 && exponent <= 1.0))
    throw std::invalid_argument("chord parameters: the exponent must be in [0, 1]");
  const std::size_t n = std::size_t(g.count);
  std::vector<double> mean(n, 0.0), row(n, 0.0);
  int used = 0;
  for (int r = 0; r < g.rows; ++r) {
    row[0] = 0.0;
    for (int k = 1; k < g.count; ++k) {
      const glm::dvec3 a(g.at(r, k - 1)), b(g.at(r, k));
      const double d = glm::length(b - a);
      if (!std::isfinite(d)) throw std::invalid_argument("chord parameters: points must be finite");
      row[std::size_t(k)] = row[std::size_t(k - 1)] + (d > 0.0 ? std::pow(d, exponent) : 0.0);
    }
    const double length = row[n - 1];
    if (!(length > 0.0)) continue;  // a collapsed polyline says nothing about the spacing
    for (std::size_t k = 0; k < n; ++k) mean[k] += row[k] / length;
    ++used;
  }
  if (n == 1) return {0.0};
  if (used == 0) {
    for (std::size_t k = 0; k < n; ++k) mean[k] = double(k) / double(n - 1);
    return mean;
  }
  for (double& t : mean) t /= double(used);
  // Exact ends (the mean of rows that all end at 1 may round a little below).
  mean.front() = 0.0;
  mean.back() = 1.0;
  return mean;
}

std::vector<double> mapParameters(const std::vector<double>& t, double start, double end) {
  std::vector<double> out(t.size());
  for (std::size_t k = 0; k < t.size(); ++k) out[k] = start + (end - start) * t[k];
  if (!out.empty() && t.back() == 1.0) out.back() = end;
  return out;
}

}  // namespace plume
