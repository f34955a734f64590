#include "tracers/point_sources.h"

#include "core/rng.h"
#include "solver/emitters.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

/// Largest float below 1: a double draw close to 1 must not round onto the next cell.
constexpr float kBelowOne = 0x1.fffffep-1f;

}  // namespace

std::vector<glm::vec3> randomPointsInCells(const CellSet& cells, glm::ivec3 resolution,
                                           float cellSize, glm::vec3 origin, int pointsPerCell,
                                           std::uint64_t seed, std::uint64_t stream) {
  if (resolution.x < 1 || resolution.y < 1 || resolution.z < 1)
    throw std::invalid_argument("resolution must be >= 1 cell per axis");
  if (!(cellSize > 0.f) || !std::isfinite(cellSize))
    throw std::invalid_argument("cell_size must be a finite number > 0 (got " +
                                std::to_string(cellSize) + ")");
  if (pointsPerCell < 1 || pointsPerCell > kMaxPointsPerCell)
    throw std::invalid_argument("point_sources must be in [1, " + std::to_string(kMaxPointsPerCell) +
                                "] per cell (got " + std::to_string(pointsPerCell) + ")");
  const std::uint64_t count =
      std::uint64_t(resolution.x) * std::uint64_t(resolution.y) * std::uint64_t(resolution.z);
  std::vector<glm::vec3> points;
  points.reserve(cells.cells.size() * std::size_t(pointsPerCell));
  Rng rng(seed, stream);
  const auto nx = std::uint64_t(resolution.x), ny = std::uint64_t(resolution.y);
  for (std::uint32_t c : cells.cells) {
    if (c >= count)
      throw std::invalid_argument("source cell index " + std::to_string(c) +
                                  " is outside the grid of " + std::to_string(count) + " cells");
    const glm::vec3 corner(float(c % nx), float((c / nx) % ny), float(c / (nx * ny)));
    for (int n = 0; n < pointsPerCell; ++n) {
      // Draw order x, y, z: part of the determinism contract.
      glm::vec3 f;
      for (int a = 0; a < 3; ++a) f[a] = std::min(float(rng.uniform()), kBelowOne);
      points.push_back(origin + (corner + f) * cellSize);
    }
  }
  return points;
}

}  // namespace plume
