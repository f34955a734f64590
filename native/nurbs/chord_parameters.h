#pragma once
/// \file chord_parameters.h
/// Parameters of the particles for the least-squares streak surface ([Smoke Surfaces] §3.3,
/// fitted instead of interpolated): averaged chord length (Piegl & Tiller, The NURBS Book,
/// eq. 9.5-9.6 and §9.2.5), so that the control points of a uniform knot vector spread evenly
/// along the smoke instead of evenly over particle indices.

#include <glm/glm.hpp>

#include <vector>

namespace plume {

/// A grid of particles seen as `rows` polylines of `count` points each: point k of row r is
/// points[first + r * rowStride + k * pointStride]. Along a streakline (u) a row is one
/// streakline; across streaklines (v) a row is one particle index.
struct PolylineGrid {
  const glm::vec3* points = nullptr;
  int count = 0;         ///< points per polyline
  int rows = 0;          ///< polylines
  long pointStride = 1;  ///< distance between consecutive points of a polyline
  long rowStride = 0;    ///< distance between consecutive polylines
  const glm::vec3& at(int row, int k) const { return points[row * rowStride + k * pointStride]; }
};

/// Averaged chord-length parameters t_0 = 0 ≤ t_1 ≤ ... ≤ t_{count-1} = 1: for every polyline
/// with a non-zero length L_r, t^r_k = (Σ_{i≤k} |p_{r,i} − p_{r,i−1}|^α) / L_r (L_r the full
/// sum); t_k is their mean. α = 1 is chord length, α = ½ centripetal (Lee 1989: spreads the parameters
/// of unevenly spaced points more evenly, so a fixed uniform knot vector has data in more of its
/// spans, and keeps curves from overshooting at sharp turns). Coincident points (particles not
/// yet apart, a line stuck on a closed side) get equal parameters: the fit sees them as one
/// point with more weight instead of a singular row. When every polyline has zero length the
/// parameters are uniform (k / (count − 1)). count = 1: {0}.
/// Throws std::invalid_argument for count < 1, rows < 1, α outside [0, 1] or non-finite points.
std::vector<double> averagedChordParameters(const PolylineGrid& grid, double exponent = 1.0);

/// t in [0, 1] mapped linearly onto [start, end] (the drawn knot interval of one direction).
std::vector<double> mapParameters(const std::vector<double>& t, double start, double end);

}  // namespace plume
