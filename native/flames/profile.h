#pragma once
/// \file profile.h
/// Normalized 2D flame profiles ([Structural Flames] §4.4, Figure 3): the silhouette r(s) of a
/// flame, s ∈ [0, 1] from the base to the tip along the spine, whose surface of revolution
/// around the spine bounds the visible (oxidization) region.
///
/// Canonical profile space (the space of eq. 4 and of the flow noise): a cylinder whose axis z is
/// the spine, lengths in units of the profile's widest radius: the surface is ρ = r(s) at
/// z = s · aspect, with max r = 1 and aspect = height / widest radius. The spine mapping
/// (spine_mapping.h) scales ρ by the flame radius R and stretches z to the spine's length.

#include <glm/glm.hpp>

#include <string>
#include <vector>

namespace plume {

/// The profile library of Figure 3 plus an artist-drawn curve.
enum class ProfileShape { Candle, Torch, Campfire, Custom };

/// A rotationally symmetric flame profile (§4.4): a polyline (s, r), closed to the axis at both
/// ends so that its surface of revolution bounds a solid.
class FlameProfile {
 public:
  /// A library profile (Candle, Torch or Campfire; Custom throws std::invalid_argument).
  static FlameProfile library(ProfileShape shape);
  /// A profile from an artist's curve: points (radius, height) in any unit, base first, heights
  /// non-decreasing (a Blender curve drawn from the base to the tip; negative radii are
  /// mirrored). Throws std::invalid_argument naming the problem (fewer than 2 points, non-finite,
  /// no height, decreasing height, zero width).
  static FlameProfile fromCurve(const std::vector<glm::dvec2>& points);

  /// r(s): the normalized radius at s (linear between points; 0 outside [0, 1]).
  double radius(double s) const;
  /// Height over widest radius (z of the tip in canonical space).
  double aspect() const { return mAspect; }
  /// The closed meridian polyline in canonical space: (ρ, z) points, base on the axis first,
  /// tip on the axis last.
  const std::vector<glm::dvec2>& meridian() const { return mMeridian; }
  /// The (s, r) points as given after normalization (max r = 1), for bindings and tests.
  const std::vector<glm::dvec2>& points() const { return mPoints; }

 private:
  FlameProfile(std::vector<glm::dvec2> sr, double aspect);
  std::vector<glm::dvec2> mPoints;    ///< (s, r), s from 0 to 1
  std::vector<glm::dvec2> mMeridian;  ///< (ρ, z) = (r, s · aspect), closed to the axis
  double mAspect = 1.0;
};

/// The profile named `name` ("candle", "torch", "campfire"); std::invalid_argument otherwise.
ProfileShape profileShapeFromName(const std::string& name);

}  // namespace plume
