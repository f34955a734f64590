#pragma once
/// \file velocity_field.h
/// External velocity fields shared by flow-graph fire and structural flames: the interface
/// u_ext(x, t) the synthesizer moves particles with ([Graph Fire Synthesis] §5.2, eq. 13:
/// "velocity introduced by (optional) external forces, useful for fire deformation"), and its
/// grid form, which flames' GridWind (flames/wind.h) reads too. The add-on evaluates Blender's
/// Wind and Turbulence force fields at cell centres once per frame.

#include "core/grid3.h"

#include <glm/glm.hpp>

namespace plume {

/// An external velocity field u_ext(x, t) (§5.2: "velocity introduced by (optional) external
/// forces, useful for fire deformation"), evaluated in batches.
class ExternalVelocity {
 public:
  virtual ~ExternalVelocity() = default;
  /// u_ext (m/s) at the n world positions x, at synthesis time t (s), into out. Called from
  /// several threads at once, on disjoint ranges.
  virtual void evaluate(const glm::vec3* x, int n, double t, glm::vec3* out) const = 0;
};

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
