#pragma once
/// \file toon_fields.h
/// The baked fields of one frame that drive the toon particles ([Cartoon Smoke] §2.1: "we
/// require only the output of a smoke simulator"): density and temperature at cell centres and
/// face velocities in m/s, on the domain grid of the bake.

#include "core/grid3.h"
#include "core/mac_grid3.h"
#include "solver/emitters.h"

#include <glm/glm.hpp>
#include <vector>

namespace plume {

/// One frame of a baked cache on its grid. `temperature` may be empty (no temperature baked: it
/// reads as 0).
struct ToonFields {
  ScalarGrid density;
  ScalarGrid temperature;
  MacGrid3 velocity;  ///< face velocities, m/s along the world axes
  /// Throws std::invalid_argument naming `what` when a grid is not on `resolution` cells.
  void validate(glm::ivec3 resolution, const char* what) const;
  /// Largest |face velocity| over the three components, m/s.
  float maxSpeed() const;
};

/// Where particles are emitted every frame (§2.1 "periodically at the smoke source"): source
/// cells (cell (i,j,k) of the grid) and points in world space, used in turn.
struct ToonSources {
  std::vector<glm::ivec3> cells;
  std::vector<glm::vec3> points;
  std::size_t size() const { return cells.size() + points.size(); }
  /// Throws std::invalid_argument for a cell outside `grid` or a point outside its box.
  void validate(const GridFrame& grid) const;
};

/// Throws std::invalid_argument unless `grid` has >= 1 cell per axis, a finite cell size > 0 and
/// a finite origin.
void validateToonGrid(const GridFrame& grid);

/// The grid of a toon build on a bake of `resolution` cells of `cellSize` metres from `origin`
/// (the frame time is unused: 1/24 s), checked by validateToonGrid().
GridFrame toonGrid(glm::ivec3 resolution, glm::vec3 origin, float cellSize);

}  // namespace plume
