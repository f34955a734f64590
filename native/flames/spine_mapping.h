#pragma once
/// \file spine_mapping.h
/// The cylindrical mapping of Figure 4 ([Structural Flames] §4.5): a point of canonical profile
/// space (x, y, z) — z along the axis in widest radii, s = z / aspect — lands at
///   X = C(s · L) + R · (x N(s) + y B(s))
/// with C the spine curve, L its arc length, R the flame's radius, and (T, N, B) a
/// rotation-minimizing frame along C (double reflection, Wang et al. 2008), so the profile does
/// not twist around a bending spine. Outside s ∈ [0, 1] (the glow below the base and above the
/// tip) the curve continues along its end tangents.
///
/// The spine is read as a dense polyline on the structure part's interpolating B-spline through
/// the flame's points (spinePolyline(), flames/spine.h), with arc length and frames tabulated.

#include "flames/flame.h"

#include <glm/glm.hpp>

#include <vector>

namespace plume {

/// A dense polyline through a flame's spine points with what each point carries, interpolated.
struct SpinePolyline {
  std::vector<glm::dvec3> x;  ///< positions, base first
  std::vector<glm::dvec3> v;  ///< dx_p/dt (eq. 1), linear between the spine points
  std::vector<double> age;    ///< t_p (eq. 2), linear between the spine points
};

/// `perSegment` points per spine segment (≥ 1) on the B-spline through flame.points (≥ 2 points).
SpinePolyline spinePolyline(const Flame& flame, int perSegment);

/// A flame's spine with arc length and a rotation-minimizing frame: the mapping of Figure 4.
class SpineFrame {
 public:
  /// From a flame (≥ 2 points; std::invalid_argument otherwise); `perSegment` as spinePolyline.
  SpineFrame(const Flame& flame, int perSegment = 4);

  /// Arc length L of the spine (m).
  double length() const { return mArc.back(); }
  /// Everything the mapping reads at one s.
  struct Point {
    glm::dvec3 c, t, n, b;  ///< C(s·L) and the frame
    glm::dvec3 v;           ///< point velocity (s clamped to [0, 1])
    double age;             ///< point age (s clamped to [0, 1])
  };
  /// The curve, frame, velocity and age at s (fraction of L; C extrapolated outside [0, 1]
  /// along the end tangents), from one table lookup.
  Point at(double s) const;
  /// Point C(s·L), tangent T, normal N, binormal B at s (as at()).
  void frameAt(double s, glm::dvec3* c, glm::dvec3* t, glm::dvec3* n, glm::dvec3* b) const;
  /// Figure 4: canonical profile position p (widest radii) of a profile of `aspect`, flame radius R.
  glm::dvec3 map(const glm::dvec3& p, double aspect, double radius) const;
  /// Interpolated point velocity and age at s (clamped to [0, 1]): at()'s v and age without the
  /// frame (the same lookup, the same values).
  void motionAt(double s, glm::dvec3* v, double* age) const;
  /// Interpolated point velocity and age at s (clamped to [0, 1]).
  glm::dvec3 velocityAt(double s) const;
  double ageAt(double s) const;
  /// Closest point of the spine polyline to x: returns s (fraction of L) and the distance.
  /// With `within` > 0, returns −1 as soon as x is known to be farther than `within`.
  double closest(const glm::dvec3& x, double* distance, double within = 0.0) const;
  /// The polyline's points, base first.
  const std::vector<glm::dvec3>& points() const { return mLine.x; }
  /// Axis-aligned bounds of the polyline.
  glm::dvec3 lower() const { return mLower; }
  glm::dvec3 upper() const { return mUpper; }

 private:
  int locate(double arc, double* f) const;
  /// at()'s curve and frame at arc length `arc` (k, f from locate()), without velocity and age.
  void frameAtArc(double arc, std::size_t k, double f, Point* p) const;
  SpinePolyline mLine;
  /// Per polyline segment k: x[k+1] − x[k], its squared length, T[k+1] − T[k] and N[k+1] − N[k]
  /// (the very differences at() and closest() would form per call, computed once).
  std::vector<glm::dvec3> mDx, mDt, mDn;
  std::vector<double> mLen2;
  std::vector<double> mArc;          ///< cumulative arc length at each polyline point
  std::vector<int> mBucket;          ///< per arc-length bucket, the last point at or below its start
  double mBucketScale = 0.0;         ///< buckets per metre of arc
  std::vector<glm::dvec3> mT, mN;    ///< tangent, normal per polyline point
  /// Groups of kGroup segments with bounding spheres (centre, radius), for closest().
  std::vector<glm::dvec4> mGroups;
  glm::dvec3 mLower{0.0}, mUpper{0.0};
};

}  // namespace plume
