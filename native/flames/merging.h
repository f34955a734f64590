#pragma once
/// \file merging.h
/// Flame merging ([Structural Flames] §4.5): after all transformations, a particle inside a
/// neighbouring flame's transformed profile and outside its own region (eq. 4's surface: it was
/// sampled in its flame's outer glow) is not rendered, so the glow of one flame does not show
/// inside another and the two read as one. Can be switched off (the paper's dragon did).
///
/// "Inside flame g" is tested through g's mapping inverted at its spine: the closest point of the
/// spine gives s and the distance ρ, and the particle is inside when s ∈ [0, 1] and
/// ρ ≤ R_g r_g(s) (exact for the undisplaced profile around a straight spine, and close around a
/// gently bending one).

#include "flames/profile.h"
#include "flames/spine_mapping.h"

#include <glm/glm.hpp>

#include <vector>

namespace plume {

/// A flame as the merging test sees it.
struct MergeVolume {
  const SpineFrame* spine = nullptr;
  const FlameProfile* profile = nullptr;
  double radius = 0.0;      ///< R (m)
  glm::dvec3 lower{0.0}, upper{0.0};  ///< a box holding its profile
  double reach = 0.0;  ///< how far (m) its own particles may lie beyond that box (glow, noise)
  /// A capsule around the chord C(0)→C(1) holding every point within R of the spine polyline
  /// (its radius R + the polyline's largest distance from the chord): a cheap exact reject.
  glm::dvec3 chordStart{0.0}, chord{0.0};
  double chordLength2 = 0.0, capsule2 = 0.0;  ///< |chord|², capsule radius² (rounded up)
};

/// A MergeVolume for a spine and profile of radius R, with a box grown by R (widest radius = 1).
MergeVolume mergeVolume(const SpineFrame& spine, const FlameProfile& profile, double radius);

/// Squared distance from x to g's chord C(0)→C(1).
double chordDistance2(const MergeVolume& g, const glm::dvec3& x);

/// Whether world x is inside flame g's transformed profile.
bool insideFlame(const MergeVolume& g, const glm::dvec3& x);

/// For each flame, the other flames whose boxes overlap its own grown by its reach (ascending).
std::vector<std::vector<int>> mergeNeighbours(const std::vector<MergeVolume>& volumes);

/// §4.5: whether a particle of flame `own` at x, inside its own surface or not, is dropped.
bool mergedAway(const std::vector<MergeVolume>& volumes, const std::vector<int>& neighbours,
                const glm::dvec3& x, bool insideOwn);

}  // namespace plume
