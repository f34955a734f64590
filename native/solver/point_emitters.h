#pragma once
/// \file point_emitters.h
/// Small spherical emitters given by a point, not a mesh: the smoke of structural flames
/// ([Structural Flames] §6.3: "smoke as particles above the tip of each flame", introduced
/// into the gas simulator with the velocity of the top control point and a temperature that
/// keeps the buoyancy of eq. 2). Unlike a Source, which holds its cells at a set density, a
/// point emitter adds a mass per second, so the smoke a flame gives off follows its radiation
/// (eq. 5) and does not depend on the grid's resolution.

#include "core/grid3.h"
#include "core/mac_grid3.h"
#include "solver/emitters.h"

#include <glm/glm.hpp>

#include <vector>

namespace plume {

/// One emitter of one frame (§6.3's smoke point of one flame).
struct PointEmitter {
  glm::vec3 position{0.f};  ///< world centre of the sphere (m)
  float radius = 0.f;       ///< sphere radius (m); at least one cell is used
  /// Smoke mass per second, Σ ρ Δx³ over the grid (density × m³ / s).
  float densityRate = 0.f;
  glm::vec3 velocity{0.f};  ///< set on the faces of the sphere's cells (m/s), §6.3's V_{p_{n-1}}
  float temperature = 0.f;  ///< T − T_amb held in the sphere's cells (the larger of this and what is there)
  /// Throws std::invalid_argument naming the setting and the accepted range.
  void validate() const;
};

/// `count` emitters from parallel arrays (the layout NumPy hands over): positions and velocities
/// as x, y, z triples, radii, density rates and temperatures one value each.
std::vector<PointEmitter> pointEmittersFrom(std::size_t count, const float* positions,
                                            const float* radii, const float* densityRates,
                                            const float* velocities, const float* temperatures);

/// Adds the emitters of one step of length dt: each puts densityRate · dt of mass into the
/// fluid cells whose centres lie within R = max(radius, Δx) of its position, weighted by
/// w = 1 − (d/R)² and normalized so that Σ ρ Δx³ grows by exactly densityRate · dt (the mass a
/// sphere reaching outside the domain or into solid cells would put there is not emitted);
/// those cells are held at least ambient + temperature hot and their faces take the velocity.
/// `cellTypes` == nullptr: every cell is fluid. Emitters are applied in order (deterministic).
void emitPoints(const std::vector<PointEmitter>& emitters, const GridFrame& grid,
                float ambientTemperature, const FlagGrid* cellTypes, float dt,
                ScalarGrid& density, ScalarGrid& temperature, MacGrid3& velocity);

}  // namespace plume
