/// \file obstacle_sdf.cpp
/// Obstacle distance fields and the push-out of control points (§6.1).

#include "flames/obstacle_sdf.h"

#include "core/sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace plume {
namespace {

bool finite(glm::dvec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

glm::dvec3 ObstacleSdf::gradient(const glm::dvec3& x) const {
  const double h = 1e-4;
  glm::dvec3 g;
  for (int a = 0; a < 3; ++a) {
    glm::dvec3 d(0.0);
    d[a] = h;
    g[a] = (distance(x + d) - distance(x - d)) / (2.0 * h);
  }
  return g;
}

SphereSdf::SphereSdf(glm::dvec3 center, double radius) : mCenter(center), mRadius(radius) {
  if (!finite(center)) throw std::invalid_argument("sphere center must be finite");
  if (!(radius > 0.0 && std::isfinite(radius)))
    throw std::invalid_argument("sphere radius must be a finite number > 0 m");
}

double SphereSdf::distance(const glm::dvec3& x) const { return glm::length(x - mCenter) - mRadius; }

BoxSdf::BoxSdf(glm::dvec3 lower, glm::dvec3 upper) {
  if (!finite(lower) || !finite(upper)) throw std::invalid_argument("box corners must be finite");
  if (!(upper.x > lower.x && upper.y > lower.y && upper.z > lower.z))
    throw std::invalid_argument("box upper corner must be > lower corner on every axis");
  mCenter = 0.5 * (lower + upper);
  mHalf = 0.5 * (upper - lower);
}

double BoxSdf::distance(const glm::dvec3& x) const {
  const glm::dvec3 q = glm::abs(x - mCenter) - mHalf;
  return glm::length(glm::max(q, glm::dvec3(0.0))) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
}

GridSdf::GridSdf(ScalarGrid values, double cellSize, glm::dvec3 origin)
    : mValues(std::move(values)), mCellSize(cellSize), mOrigin(origin) {
  const glm::ivec3 n = mValues.size();
  if (n.x < 1 || n.y < 1 || n.z < 1) throw std::invalid_argument("obstacle SDF grid must have >= 1 cell per axis");
  if (!(cellSize > 0.0 && std::isfinite(cellSize)))
    throw std::invalid_argument("obstacle SDF cell_size must be a finite number > 0 m");
  if (!finite(origin)) throw std::invalid_argument("obstacle SDF origin must be finite");
  for (float v : mValues.values())
    if (!std::isfinite(v)) throw std::invalid_argument("obstacle SDF grid holds a non-finite value");
}

double GridSdf::distance(const glm::dvec3& x) const {
  // Outside the grid, the clamped value plus the distance to the grid box keeps φ growing.
  const glm::dvec3 p = (x - mOrigin) / mCellSize - glm::dvec3(0.5);
  const glm::dvec3 hi = glm::dvec3(mValues.size() - glm::ivec3(1));
  const glm::dvec3 c = glm::clamp(p, glm::dvec3(0.0), hi);
  return double(sampleLinear(mValues, glm::vec3(c))) + glm::length(p - c) * mCellSize;
}

void ObstacleSet::add(std::shared_ptr<const ObstacleSdf> obstacle) {
  if (!obstacle) throw std::invalid_argument("obstacle must not be None");
  mObstacles.push_back(std::move(obstacle));
}

double ObstacleSet::distance(const glm::dvec3& x) const {
  double d = std::numeric_limits<double>::infinity();
  for (const auto& o : mObstacles) d = std::min(d, o->distance(x));
  return d;
}

bool ObstacleSet::pushOut(glm::dvec3& x, double margin, const glm::dvec3& fallback) const {
  bool moved = false;
  // Each pass projects onto the nearest obstacle's level set φ = margin; overlapping obstacles or
  // approximate (grid) fields may need a few.
  for (int pass = 0; pass < 16; ++pass) {
    const ObstacleSdf* nearest = nullptr;
    double d = std::numeric_limits<double>::infinity();
    for (const auto& o : mObstacles) {
      const double od = o->distance(x);
      if (od < d) d = od, nearest = o.get();
    }
    if (!nearest || d >= margin) return moved;
    glm::dvec3 g = nearest->gradient(x);
    const double len = glm::length(g);
    if (len > 1e-6) {
      g /= len;
    } else {
      const double f = glm::length(fallback);
      g = f > 1e-12 ? fallback / f : glm::dvec3(0.0, 0.0, 1.0);
    }
    // Step a little past the level set (1e-9 m) so rounding cannot leave it a hair inside.
    x += (margin - d + 1e-9) * g;
    moved = true;
  }
  return moved;
}

}  // namespace plume
