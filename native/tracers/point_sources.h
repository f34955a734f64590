#pragma once
/// \file point_sources.h
/// Point sources of streaklines placed at random inside source cells ([Smoke Surfaces] §3.2:
/// "10–20 point sources are placed randomly in a source cell").

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace plume {

struct CellSet;

/// `pointsPerCell` world positions uniform inside each cell of `cells` (linear indices
/// i + nx*(j + ny*k) of a grid of `resolution` cells of size `cellSize` whose minimum corner is
/// `origin`), [Smoke Surfaces] §3.2. Point n lies in cells.cells[n / pointsPerCell]. One
/// Rng(seed, stream) is consumed in cell order, three draws per point, so the result depends only
/// on the arguments. Throws std::invalid_argument naming the setting for a bad resolution,
/// cell size, point count or a cell index outside the grid.
std::vector<glm::vec3> randomPointsInCells(const CellSet& cells, glm::ivec3 resolution,
                                           float cellSize, glm::vec3 origin, int pointsPerCell,
                                           std::uint64_t seed, std::uint64_t stream = 0);

/// Largest accepted points per cell (the paper uses 10–20).
constexpr int kMaxPointsPerCell = 10000;

}  // namespace plume
