#pragma once
/// \file advection.h
/// Semi-Lagrangian advection (Stam 1999) and BFECC (Kim, Liu, Llamas & Rossignac 2005) with a
/// clamp limiter, for cell-centred scalars and the staggered velocity components.

#include "core/grid3.h"
#include "core/mac_grid3.h"
#include "core/sampling.h"
#include "solver/smoke_params.h"

namespace plume {

/// Where sample (0,0,0) of a grid sits, in cell coordinates: cells at 0, u-faces at (-½,0,0)...
constexpr glm::vec3 kCellOffset{0.f, 0.f, 0.f};
constexpr glm::vec3 kFaceOffsetU{-0.5f, 0.f, 0.f};
constexpr glm::vec3 kFaceOffsetV{0.f, -0.5f, 0.f};
constexpr glm::vec3 kFaceOffsetW{0.f, 0.f, -0.5f};

/// Back-traced position of p (cell coordinates) after `cells` = dt/Δx seconds-per-metre through
/// the velocity field: explicit midpoint rule (RK2), second order in time.
glm::vec3 traceBack(const MacGrid3& velocity, glm::vec3 p, float cells);

/// Carries grids through a velocity field. Owns the scratch grids BFECC needs, sized once.
class Advector {
 public:
  /// Reserves scratch for grids of up to `count` samples (no allocation afterwards).
  void reserve(std::size_t count);

  /// dst = src advected for dt along `velocity`. `offset` says where src's samples sit
  /// (kCellOffset, kFaceOffsetU...). With BFECC: φ̂ = A(φ), φ̄ = A⁻¹(φ̂),
  /// result = A(φ + ½(φ - φ̄)) clamped to the range of φ around the back-traced point.
  /// dst must not alias src or velocity.
  void advect(const ScalarGrid& src, ScalarGrid& dst, glm::vec3 offset, const MacGrid3& velocity,
              float dt, float cellSize, Advection scheme, Interpolation interpolation);

 private:
  ScalarGrid mForward, mBackward;
};

}  // namespace plume
