/// \file toon_fields.cpp
/// Checks of the per-frame fields and sources that drive the toon particles.

#include "toon/toon_fields.h"

#include "core/parallel.h"

#include <smmintrin.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

std::string text(glm::ivec3 v) {
  return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// Largest |v[n]| over n < count, four lanes at a time (the compiler does not vectorize a float
/// max reduction on its own). `n` values are already folded into the lanes of m.
float maxAbs(const float* v, std::size_t count, __m128 m = _mm_setzero_ps(), std::size_t n = 0) {
  const __m128 sign = _mm_set1_ps(-0.f);
  for (; n + 4 <= count; n += 4) m = _mm_max_ps(m, _mm_andnot_ps(sign, _mm_loadu_ps(v + n)));
  alignas(16) float lanes[4];
  _mm_store_ps(lanes, m);
  float r = std::max(std::max(lanes[0], lanes[1]), std::max(lanes[2], lanes[3]));
  for (; n < count; ++n) r = std::max(r, std::abs(v[n]));
  return r;
}

/// maxAbs() with four independent running maxima over the first 16k values (one chain of
/// dependent max_ps is latency bound). The maximum of numbers does not depend on the order, so
/// the result is maxAbs()'s bit for bit; where a NaN lies among those values (maxAbs's result
/// then depends on its place), maxAbs() itself runs.
float maxAbsWide(const float* v, std::size_t count) {
  const __m128 sign = _mm_set1_ps(-0.f);
  __m128 m[4] = {_mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps()};
  __m128 nan = _mm_setzero_ps();
  std::size_t n = 0;
  for (; n + 16 <= count; n += 16)
    for (int k = 0; k < 4; ++k) {
      const __m128 a = _mm_andnot_ps(sign, _mm_loadu_ps(v + n + 4 * std::size_t(k)));
      nan = _mm_or_ps(nan, _mm_cmpunord_ps(a, a));
      m[k] = _mm_max_ps(m[k], a);
    }
  if (_mm_movemask_ps(nan) != 0) return maxAbs(v, count);
  return maxAbs(v, count, _mm_max_ps(_mm_max_ps(m[0], m[1]), _mm_max_ps(m[2], m[3])), n);
}

}  // namespace

void ToonFields::validate(glm::ivec3 resolution, const char* what) const {
  if (density.size() != resolution || velocity.cells() != resolution ||
      (temperature.count() != 0 && temperature.size() != resolution))
    throw std::invalid_argument(std::string("toon particles: the ") + what +
                                " fields are not on the particles' grid " + text(resolution) +
                                " (density " + text(density.size()) + ", velocity " +
                                text(velocity.cells()) + ")");
}

float ToonFields::maxSpeed() const {
  double m = 0.0;
  for (int a = 0; a < 3; ++a) {
    const ScalarGrid& c = velocity.component(a);
    const glm::ivec3 s = c.size();
    const std::size_t slab = std::size_t(s.x) * std::size_t(s.y);
    m = std::max(m, parallelMax(0, s.z, [&](int k) {
                   return double(maxAbsWide(c.data() + std::size_t(k) * slab, slab));
                 }));
  }
  return float(m);
}

void ToonSources::validate(const GridFrame& grid) const {
  for (std::size_t n = 0; n < cells.size(); ++n) {
    const glm::ivec3 c = cells[n];
    if (glm::any(glm::lessThan(c, glm::ivec3(0))) ||
        glm::any(glm::greaterThanEqual(c, grid.resolution)))
      throw std::invalid_argument("toon source cell " + std::to_string(n) + " " + text(c) +
                                  " lies outside the grid " + text(grid.resolution));
  }
  const glm::vec3 hi = grid.origin + glm::vec3(grid.resolution) * grid.cellSize;
  for (std::size_t n = 0; n < points.size(); ++n) {
    const glm::vec3 p = points[n];
    if (!finite(p) || glm::any(glm::lessThan(p, grid.origin)) || glm::any(glm::greaterThan(p, hi)))
      throw std::invalid_argument("toon source point " + std::to_string(n) +
                                  " must be finite and inside the domain box");
  }
}

void validateToonGrid(const GridFrame& grid) {
  if (glm::any(glm::lessThan(grid.resolution, glm::ivec3(1))))
    throw std::invalid_argument("resolution must be >= 1 cell per axis (got " +
                                text(grid.resolution) + ")");
  if (!(grid.cellSize > 0.f) || !std::isfinite(grid.cellSize))
    throw std::invalid_argument("cell_size must be a finite number > 0 metres (got " +
                                std::to_string(grid.cellSize) + ")");
  if (!finite(grid.origin)) throw std::invalid_argument("origin must be finite");
}

GridFrame toonGrid(glm::ivec3 resolution, glm::vec3 origin, float cellSize) {
  const GridFrame grid{resolution, cellSize, origin, 1.f / 24.f};
  validateToonGrid(grid);
  return grid;
}

}  // namespace plume
