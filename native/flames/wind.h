#pragma once
/// \file wind.h
/// The controlling wind field w(x_p, t) of eq. 1 ([Structural Flames] §4.2, §6: "global motion
/// is dictated by the summation of different kinds of wind field"): small fields summed by a
/// CompositeWind — uniform wind (Blender's Wind force field: direction · strength), a vortex
/// (Blender's Vortex), divergence-free turbulence (Blender's Turbulence), and a velocity grid
/// (a Plume solver cache, cell-centred or MAC; §6.1 wind around obstacles).

#include "core/grid3.h"
#include "core/mac_grid3.h"
#include "fields/velocity_field.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace plume {

/// w(x, t) of eq. 1 (m/s). evaluate() is called from several threads at once.
class WindField {
 public:
  virtual ~WindField() = default;
  /// Wind velocity at world position x (m) and time t (s).
  virtual glm::dvec3 evaluate(const glm::dvec3& x, double t) const = 0;
};

/// A constant wind (Blender's Wind field: velocity = direction · strength).
class UniformWind final : public WindField {
 public:
  explicit UniformWind(glm::dvec3 velocity);
  glm::dvec3 evaluate(const glm::dvec3& x, double t) const override;

 private:
  glm::dvec3 mVelocity;
};

/// Rotation about an axis through `center` (Blender's Vortex field): tangential speed `strength`
/// (m/s, positive = counter-clockwise seen from the axis tip) beyond `coreRadius`, solid-body
/// rotation inside it (so the field is finite on the axis).
class VortexWind final : public WindField {
 public:
  VortexWind(glm::dvec3 center, glm::dvec3 axis, double strength, double coreRadius);
  glm::dvec3 evaluate(const glm::dvec3& x, double t) const override;

 private:
  glm::dvec3 mCenter, mAxis;
  double mStrength, mCoreRadius;
};

/// Divergence-free noise (Blender's Turbulence field): the curl of a vector potential made of
/// `modes` random plane waves ψ = Σ a_k sin(k·x + ω_k t + φ_k) with |k| ~ 2π/size, so
/// w = ∇×ψ = Σ (k × a_k) cos(k·x + ω_k t + φ_k) has zero divergence exactly. Scaled so the rms speed
/// is `strength`; `flow` (Hz) sets how fast the pattern changes.
class TurbulenceWind final : public WindField {
 public:
  TurbulenceWind(double strength, double size, double flow, std::uint64_t seed, int modes = 16);
  glm::dvec3 evaluate(const glm::dvec3& x, double t) const override;

 private:
  struct Mode {
    glm::dvec3 k, amplitude;  // amplitude = k × a_k, scaled
    double omega, phase;
  };
  std::vector<Mode> mModes;
};

/// Velocity on a cell-centred grid (value (i,j,k) at origin + (i+½, j+½, k+½)·Δx), read
/// trilinearly with clamping (GridVelocityField, shared with flow-graph synthesis).
class GridWind final : public WindField {
 public:
  /// Throws std::invalid_argument for an empty grid, a bad cell size or non-finite values.
  GridWind(VectorGrid values, double cellSize, glm::dvec3 origin);
  glm::dvec3 evaluate(const glm::dvec3& x, double t) const override;

 private:
  GridVelocityField mField;
};

/// Velocity on a staggered (MAC) grid of nx·ny·nz cells as the solver stores it, each component
/// read trilinearly from its faces (sampleVelocity()).
class MacWind final : public WindField {
 public:
  /// Throws std::invalid_argument for an empty grid, a bad cell size or non-finite values.
  MacWind(MacGrid3 velocity, double cellSize, glm::dvec3 origin);
  glm::dvec3 evaluate(const glm::dvec3& x, double t) const override;

 private:
  MacGrid3 mVelocity;
  double mInvCellSize;
  glm::dvec3 mOrigin;
};

/// The sum of several fields (§6: wind fields add up); empty = still air.
class CompositeWind final : public WindField {
 public:
  void add(std::shared_ptr<const WindField> field);
  void clear() { mFields.clear(); }
  std::size_t size() const { return mFields.size(); }
  glm::dvec3 evaluate(const glm::dvec3& x, double t) const override;

 private:
  std::vector<std::shared_ptr<const WindField>> mFields;
};

}  // namespace plume
