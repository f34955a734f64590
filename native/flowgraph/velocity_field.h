#pragma once
/// \file velocity_field.h
/// An external velocity u_ext(x) for synthesis (graph_fire_synthesis.txt §5.2, eq. 13: "velocity
/// introduced by (optional) external forces, useful for fire deformation") given on a grid: the
/// add-on evaluates Blender's Wind and Turbulence force fields at cell centres once per frame.

#include "core/grid3.h"
#include "flowgraph/synthesizer.h"

#include <glm/glm.hpp>

namespace plume {

/// u_ext on a cell-centred grid: value (i,j,k) at origin + (i + 1/2, j + 1/2, k + 1/2) Δx, read
/// trilinearly; positions outside take the nearest values (clamped). Constant in time between
/// updates (the caller replaces the field once per frame).
class GridVelocityField final : public ExternalVelocity {
 public:
  /// Throws std::invalid_argument for an empty grid, a cell size that is not a finite number
  /// > 0, or non-finite values.
  GridVelocityField(VectorGrid values, float cellSize, glm::vec3 origin);
  void evaluate(const glm::vec3* x, int n, double t, glm::vec3* out) const override;
  /// u_ext at one world position.
  glm::vec3 at(glm::vec3 x) const;
  const VectorGrid& values() const { return mValues; }

 private:
  VectorGrid mValues;
  float mInvCellSize;
  glm::vec3 mOrigin;
};

}  // namespace plume
