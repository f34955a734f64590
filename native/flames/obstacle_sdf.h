#pragma once
/// \file obstacle_sdf.h
/// Stationary objects for flame interaction ([Structural Flames] §6.1): "after their positions
/// are modified they are tested against the object volume and moved outside if there's a
/// conflict". An obstacle is a signed distance φ (negative inside, metres); control points with
/// φ < margin are pushed along ∇φ.

#include "core/grid3.h"

#include <glm/glm.hpp>

#include <memory>
#include <vector>

namespace plume {

/// A signed distance field φ(x): < 0 inside, > 0 outside (m). Called from several threads.
class ObstacleSdf {
 public:
  virtual ~ObstacleSdf() = default;
  /// φ(x) (m).
  virtual double distance(const glm::dvec3& x) const = 0;
  /// ∇φ(x); by default central differences with step 1e-4 m.
  virtual glm::dvec3 gradient(const glm::dvec3& x) const;
};

/// A solid sphere.
class SphereSdf final : public ObstacleSdf {
 public:
  SphereSdf(glm::dvec3 center, double radius);
  double distance(const glm::dvec3& x) const override;

 private:
  glm::dvec3 mCenter;
  double mRadius;
};

/// A solid axis-aligned box (exact signed distance).
class BoxSdf final : public ObstacleSdf {
 public:
  BoxSdf(glm::dvec3 lower, glm::dvec3 upper);
  double distance(const glm::dvec3& x) const override;

 private:
  glm::dvec3 mCenter, mHalf;
};

/// A voxelized obstacle: φ on a cell-centred grid (value (i,j,k) at origin + (i+½, j+½, k+½)·Δx),
/// read trilinearly (the add-on's mesh-to-volume level set).
class GridSdf final : public ObstacleSdf {
 public:
  /// Throws std::invalid_argument for an empty grid, a bad cell size or non-finite values.
  GridSdf(ScalarGrid values, double cellSize, glm::dvec3 origin);
  double distance(const glm::dvec3& x) const override;

 private:
  ScalarGrid mValues;
  double mCellSize;
  glm::dvec3 mOrigin;
};

/// Several obstacles: φ = min over them (the union of solids).
class ObstacleSet {
 public:
  void add(std::shared_ptr<const ObstacleSdf> obstacle);
  void clear() { mObstacles.clear(); }
  bool empty() const { return mObstacles.empty(); }
  double distance(const glm::dvec3& x) const;
  /// Moves x out of every obstacle to φ >= margin along ∇φ of the nearest one (a few projection
  /// steps; exact in one for true distance fields). Where ∇φ vanishes (a sphere's centre, a box's
  /// medial planes) the ambiguity is resolved with `fallback`, the direction towards the adjacent
  /// control point (§6.1: "resolved using the adjacency of the points themselves"). Returns
  /// whether x was moved.
  bool pushOut(glm::dvec3& x, double margin, const glm::dvec3& fallback) const;

 private:
  std::vector<std::shared_ptr<const ObstacleSdf>> mObstacles;
};

}  // namespace plume
