#pragma once
/// \file profile_density.h
/// The light density of a flame ([Structural Flames] §4.4, eq. 4) in canonical profile space
/// (profile.h), and its Monte-Carlo sampling:
///   d(x) = I / (1 + |x_f(x) − x|² / ℓ²)   outside the surface,   d(x) = I inside it
/// x_f(x) the closest point to x on the surface of revolution of the profile. Eq. 4 defines "the
/// light density of the visible part of the flame" around the surface where I is "the density
/// of combustion at the surface"; read literally inside too, the density would fall towards the
/// axis and the flame would render as a hollow shell (a bright rim, a dark core), which no
/// photograph of a flame shows. The region the profile bounds is the visible flame (§4.4:
/// "the surface of revolution bounds the visible (oxidization) region"), so it is filled at I
/// and eq. 4's fall-off is the glow outside it. Eq. 4 as printed
/// has ℓ = 1 in the paper's (unstated) normalized units; here distances are in units of the
/// profile's widest radius and ℓ (`falloff`) sets how far the glow reaches, so ℓ = 1 is eq. 4
/// literally. The density is sampled inside the shell |x_f(x) − x| ≤ cutoff · ℓ (eq. 4 decays as
/// 1/dist², so its integral over all space diverges: some bound is needed). Over the shell's
/// outer half eq. 4 is faded to 0 by a smoothstep window W (glowWindow()), so the glow ends
/// softly: cut off plainly, it stopped at d = I / (1 + cutoff²) (I/5 at the default cutoff, and
/// the emission, ∝ d², at 4 % of the surface's) and showed a hard edge, e.g. a band with a
/// straight border on the ground beside a campfire's logs. At the default cutoff (2) the window
/// starts at distance ℓ, so d still falls to I/2 there.
///
/// Built once per profile: a grid over the meridian half-plane (ρ, z) holding, per cell, the
/// profile segments that can be closest to any point of the cell (exact closest points at the
/// cost of one or two segments), and the cell's mass ∫ 2πρ d dρ dz by 4×4 midpoint quadrature.
/// Sampling is stratified over the cells' cumulative mass, cells ordered by their mean d (sample
/// n of N takes u = (n + ξ)/N), and exact inside a cell by rejection, so the samples follow d exactly up to the quadrature of
/// the cell masses, and the mean of d(x_i) converges much faster than 1/√N.

#include "core/rng.h"
#include "flames/profile.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace plume {

/// Eq. 4's fade over the outer half of the sampling shell: 1 at distances up to shell/2, then a
/// smoothstep down to 0 at `shell` (and beyond).
double glowWindow(double dist, double shell);

/// Settings of eq. 4 and of its sampling shell.
struct DensityParams {
  double falloff = 0.5;  ///< ℓ, in widest radii: d falls to I/2 at distance ℓ from the surface
  double cutoff = 2.0;   ///< the shell sampled: distances up to cutoff · ℓ, eq. 4 faded to 0 there
  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
};

/// One sample of eq. 4 in canonical profile space.
struct ProfileSample {
  glm::dvec3 position{0.0};  ///< (x, y, z): z along the axis, ρ = |(x, y)|
  double density = 0.0;      ///< d(x) / I
  bool inside = false;       ///< inside the surface of revolution (its own region, §4.5)
};

/// Eq. 4 for one profile, with the tables for exact closest points and for sampling.
class ProfileDensity {
 public:
  /// Builds the tables (a few ms). Throws std::invalid_argument on bad params.
  ProfileDensity(const FlameProfile& profile, const DensityParams& params);

  /// The closest point x_f on the meridian polyline to (ρ, z) (ρ ≥ 0), and its distance.
  glm::dvec2 closestPoint(glm::dvec2 rhoZ, double* distance) const;
  /// |x_f − x| outside the surface of revolution, 0 inside it.
  double surfaceDistance(glm::dvec2 rhoZ) const;
  /// d(x)/I (eq. 4 with I = 1 times glowWindow(), and 1 inside the surface) at a canonical
  /// position: 0 beyond the shell.
  double density(const glm::dvec3& p) const;
  /// Whether (ρ, z) is inside the surface of revolution.
  bool inside(glm::dvec2 rhoZ) const;

  /// Sample of d restricted to the shell; `u` ∈ [0, 1) picks the stratum (cumulative cell mass),
  /// `rng` places the sample inside it.
  ProfileSample sample(double u, Rng& rng) const;
  /// ⟨d⟩/I, the expected d(x_i)/I of a sample (∫ d² dV / ∫ d dV over the shell, by quadrature):
  /// eq. 6's "energy loss due to the d(x_i) term" (§5.2).
  double meanDensity() const { return mMeanDensity; }
  /// ∫ d/I dV over the shell, in widest radii cubed.
  double mass() const { return mMass; }

  const FlameProfile& profile() const { return mProfile; }
  const DensityParams& params() const { return mParams; }
  /// The sampled box in the meridian plane: ρ ∈ [0, rhoMax], z ∈ [zMin, zMax].
  double rhoMax() const { return mRhoMax; }
  double zMin() const { return mZMin; }
  double zMax() const { return mZMax; }

 private:
  double distanceToSegment(int segment, glm::dvec2 p, glm::dvec2* closest) const;
  /// Its square (no square root), the same closest point.
  double distance2ToSegment(int segment, glm::dvec2 p, glm::dvec2* closest) const;
  int cellOf(glm::dvec2 rhoZ) const;
  /// Fills mCellSide.
  void classifyCells();

  FlameProfile mProfile;
  DensityParams mParams;
  double mShell = 0.0;  ///< cutoff · ℓ
  double mRhoMax = 0.0, mZMin = 0.0, mZMax = 0.0, mCell = 0.0;
  int mNr = 0, mNz = 0;
  std::vector<glm::dvec2> mSegA, mSegAb;  ///< per meridian segment: its start a and b − a
  std::vector<double> mSegLen2;           ///< per meridian segment: |b − a|²
  std::vector<glm::dvec2> mCellOrigin;    ///< per cell: its (ρ, z) corner
  std::vector<int> mCandidateStart;   ///< per cell, into mCandidates (size cells + 1)
  std::vector<int> mCandidates;       ///< segment indices
  std::vector<int> mOrder;            ///< cells by increasing mean d: the strata's order
  std::vector<double> mCumulative;    ///< cumulative cell mass in that order, ending at 1
  std::vector<int> mGuide;            ///< per u bucket of width 1/size: upper_bound of its start
  std::vector<double> mCellMaxDensity;  ///< an upper bound of d in the cell (rejection)
  /// Per cell: kInside (every point inside the surface: d = 1, no distance query), kOutside (no
  /// point inside: no inside() test), kMixed.
  std::vector<std::uint8_t> mCellSide;
  std::vector<glm::dvec2> mCellRadius;  ///< per cell: the profile radius's (min, max) over its z
  double mMass = 0.0, mMeanDensity = 0.0;
};

}  // namespace plume
