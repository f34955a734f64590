#pragma once
/// \file spine.h
/// The base curve of a flame ([Structural Flames] §4.1): "an interpolating B-Spline curve ...
/// fitted so that it passes through all the points. This curve is then parametrically re-sampled,
/// generating a new set of n points (always keeping the first and last unchanged)."

#include "flames/flame.h"

#include <glm/glm.hpp>

#include <vector>

namespace plume {

/// The interpolating cubic B-spline through points P_0..P_{m-1} with chord-length parameters
/// u_0 = 0, u_{k+1} = u_k + |P_{k+1} − P_k| and natural ends (zero second derivative): the C²
/// cubic B-spline whose curve passes through every P_k at u_k, stored per span as its cubic.
/// Coincident consecutive points are merged (they carry no direction). Arc length by 5-point
/// Gauss–Legendre quadrature on four sub-intervals per span (exact to ~1e-10 relative for the
/// gently bent spines of flames).
class Spine {
 public:
  Spine() = default;
  /// Fits the curve through points (at least 1; a single distinct point gives a zero-length curve).
  explicit Spine(const std::vector<glm::dvec3>& points);
  /// The curve through the positions of a flame's spine points.
  static Spine fit(const std::vector<SpinePoint>& points);

  /// Chord-length parameters of the distinct points kept (u_0 = 0 ... u_{m-1} = parameterEnd()).
  const std::vector<double>& knots() const { return mKnots; }
  /// For each knot, the index of the input point it came from.
  const std::vector<int>& sourceIndices() const { return mSource; }
  /// The last parameter U (total chord length).
  double parameterEnd() const { return mKnots.empty() ? 0.0 : mKnots.back(); }
  /// C(u) for u in [0, U] (clamped).
  glm::dvec3 evaluate(double u) const;
  /// dC/du (not normalized; |dC/du| ≈ 1 for chord-length parameters).
  glm::dvec3 derivative(double u) const;
  /// Unit tangent at u (the chord to the next point where the derivative vanishes).
  glm::dvec3 tangent(double u) const;
  /// Total arc length L (m).
  double length() const { return mTable.empty() ? 0.0 : mTable.back(); }
  /// Arc length s(u) from the base to C(u).
  double arcLength(double u) const;
  /// The parameter u with s(u) = s (s clamped to [0, L]), by safeguarded Newton steps.
  double parameterAt(double s) const;

 private:
  int spanOf(double u) const;
  /// C'(u_k) of span k (the cubic's linear coefficient), and C' at t = u − u_k inside span k.
  glm::dvec3 spanSlope(int span) const;
  glm::dvec3 spanDerivative(int span, double t) const;
  double spanArc(int span, double t0, double t1) const;

  std::vector<double> mKnots;
  std::vector<int> mSource;
  std::vector<glm::dvec3> mPoints;  // P_k of the kept knots
  std::vector<glm::dvec3> mSecond;  // C''(u_k)
  std::vector<double> mTable;       // arc length at the ends of the 4 sub-intervals of each span, from 0
};

/// Re-samples (§4.1): `count` points (>= 2) spaced evenly along the arc length of the curve through
/// `points` over [s0, s1] (m from the base; clamped to [0, L]). An end at 0 or L is the original
/// first or last point exactly. Ages and velocities are interpolated linearly in u between the
/// neighbouring input points.
std::vector<SpinePoint> resampleSpine(const Spine& spine, const std::vector<SpinePoint>& points,
                                      double s0, double s1, int count);

/// resampleSpine() over the whole curve: the n points of §4.1 with first and last unchanged.
std::vector<SpinePoint> resampleSpine(const std::vector<SpinePoint>& points, int count);

/// Arc length of the polyline through the points' positions (m).
double polylineLength(const std::vector<SpinePoint>& points);

}  // namespace plume
