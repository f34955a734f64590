/// \file velocity_field.cpp
/// The grid form of an external velocity field, shared by flow-graph synthesis and flames'
/// GridWind (see velocity_field.h): trilinear reads with clamping.

#include "fields/velocity_field.h"

#include "core/sample_points.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {

GridVelocityField::GridVelocityField(VectorGrid values, float cellSize, glm::vec3 origin)
    : mValues(std::move(values)), mOrigin(origin) {
  const glm::ivec3 n = mValues.size();
  if (n.x < 1 || n.y < 1 || n.z < 1 || mValues.count() == 0)
    throw std::invalid_argument("external velocity field must have >= 1 cell per axis");
  if (!(cellSize > 0.f) || !std::isfinite(cellSize))
    throw std::invalid_argument("external velocity cell_size must be a finite number > 0 (got " +
                                std::to_string(cellSize) + ")");
  if (!std::isfinite(origin.x) || !std::isfinite(origin.y) || !std::isfinite(origin.z))
    throw std::invalid_argument("external velocity origin must be finite");
  for (const glm::vec3& v : mValues.values())
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
      throw std::invalid_argument("external velocity field holds a non-finite value");
  mInvCellSize = 1.f / cellSize;
}

glm::vec3 GridVelocityField::at(glm::vec3 x) const {
  const glm::ivec3 n = mValues.size();
  const glm::vec3 c = (x - mOrigin) * mInvCellSize - glm::vec3(0.5f);
  int i, j, k;
  float tx, ty, tz;
  splitCoordinate(c.x, n.x, i, tx);
  splitCoordinate(c.y, n.y, j, ty);
  splitCoordinate(c.z, n.z, k, tz);
  // After splitCoordinate() the +1 neighbour exists on every axis longer than one sample.
  const int i1 = n.x > 1 ? i + 1 : i, j1 = n.y > 1 ? j + 1 : j, k1 = n.z > 1 ? k + 1 : k;
  auto lerp = [](glm::vec3 a, glm::vec3 b, float t) { return a + t * (b - a); };
  const glm::vec3 c00 = lerp(mValues(i, j, k), mValues(i1, j, k), tx);
  const glm::vec3 c10 = lerp(mValues(i, j1, k), mValues(i1, j1, k), tx);
  const glm::vec3 c01 = lerp(mValues(i, j, k1), mValues(i1, j, k1), tx);
  const glm::vec3 c11 = lerp(mValues(i, j1, k1), mValues(i1, j1, k1), tx);
  return lerp(lerp(c00, c10, ty), lerp(c01, c11, ty), tz);
}

void GridVelocityField::evaluate(const glm::vec3* x, int n, double, glm::vec3* out) const {
  for (int m = 0; m < n; ++m) out[m] = at(x[m]);
}

}  // namespace plume
