#pragma once
/// \file sampling.h
/// Trilinear and monotonic cubic sampling of a grid (Fedkiw, Stam & Jensen 2001, §5;
/// [Smoke Surfaces] §3.1 uses it to keep small rolling features).

#include "core/grid3.h"
#include "core/mac_grid3.h"

namespace plume {

/// How advection and tracers read a grid between its samples.
enum class Interpolation { Linear, MonotonicCubic };

/// Trilinear sample at p in the grid's index space (sample (i,j,k) sits at p = (i,j,k)).
/// Positions outside are clamped to the grid.
float sampleLinear(const ScalarGrid& grid, glm::vec3 p);

/// Monotonic cubic sample (Fedkiw 2001 eq. 12-13): Hermite cubic whose slopes d_k are central
/// differences, zeroed when they disagree in sign with Δ_k = f_{k+1} - f_k, and limited to 3|Δ_k|
/// (Fritsch & Carlson) so that no new extrema appear. Applied per axis (x, then y, then z).
float sampleMonotonicCubic(const ScalarGrid& grid, glm::vec3 p);

/// sampleMonotonicCubic() at four points p[0..3] into out[0..3]: the same values, with the last
/// (z) cubic of the four samples computed together. Advection samples runs of points this way.
void sampleMonotonicCubic4(const ScalarGrid& grid, const glm::vec3* p, float* out);

/// Dispatches on the interpolation scheme.
inline float sample(const ScalarGrid& grid, glm::vec3 p, Interpolation scheme) {
  return scheme == Interpolation::Linear ? sampleLinear(grid, p) : sampleMonotonicCubic(grid, p);
}

/// Smallest and largest of the 8 samples around p (the stencil of a trilinear sample); BFECC's
/// clamp limiter keeps its result inside this range.
void sampleRange(const ScalarGrid& grid, glm::vec3 p, float& lo, float& hi);

/// Velocity of a MAC grid at p in cell coordinates (cell (i,j,k)'s centre is p = (i,j,k)),
/// each component read trilinearly from its own faces. Units are those of the grid (m/s).
glm::vec3 sampleVelocity(const MacGrid3& velocity, glm::vec3 p);

/// Same, with the chosen interpolation for every component (tracers use the solver's scheme).
glm::vec3 sampleVelocity(const MacGrid3& velocity, glm::vec3 p, Interpolation scheme);

/// The 1-D monotone cubic Hermite interpolant between f1 and f2 at t in [0,1], with f0 and f3 the
/// outer neighbours. Exposed for the unit tests.
float monotonicCubic1D(float f0, float f1, float f2, float f3, float t);

}  // namespace plume
