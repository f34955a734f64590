#pragma once
/// \file least_squares.h
/// One direction of the least-squares streak surface ([Smoke Surfaces] §3.3, with fewer
/// control points than particles so the net stays on the smoke): a B-spline curve on Blender's
/// knots fitted to data at given parameters (Piegl & Tiller, The NURBS Book §9.4.1) with a small
/// penalty on the control polygon's second divided differences, which keeps the normal
/// equations non-singular where a knot span holds no data and makes such spans straight.

#include "nurbs/banded_lu.h"
#include "nurbs/basis.h"

#include <glm/glm.hpp>

#include <vector>

namespace plume {

/// The factorised normal equations (BᵀB + λR) c = Bᵀq of one direction, for data at fixed
/// parameters: B_ij = N_j(t_i) on blenderKnots(count, order, endpoint); R = DᵀD with
/// (Dc)_j = h̄ [(c_{j+1} − c_j)/(ḡ_{j+1} − ḡ_j) − (c_j − c_{j−1})/(ḡ_j − ḡ_{j−1})] on the
/// Greville abscissae ḡ (so a straight line costs nothing) and h̄ their mean spacing; λ = smoothing ·
/// trace(BᵀB) / trace(R), so `smoothing` is the penalty's weight relative to the data whatever
/// the counts. Fewer than two distinct parameters (one particle, or all coincident): the curve
/// is the constant mean of the data. Built once per set of parameters, applied to many rows.
class CurveFitter {
 public:
  /// Throws std::invalid_argument unless params is non-empty, finite and inside the drawn
  /// domain of the knots, 2 <= order <= count (order <= 6) and smoothing is finite, >= 0.
  /// smoothing = 0 with too few data per span throws std::runtime_error (singular system).
  CurveFitter(const std::vector<double>& params, int count, int order, bool endpoint,
              double smoothing);

  int count() const { return mCount; }
  int order() const { return mOrder; }
  std::size_t dataCount() const { return mRows.size(); }
  /// t_i, the parameter of datum i < dataCount().
  double parameter(std::size_t i) const { return mParams.at(i); }

  /// Control points (count of them, at out[j * outStride]) of the fit to the data
  /// q_i = data[i * stride], i < dataCount().
  void fit(const glm::dvec3* data, long stride, glm::dvec3* out, long outStride) const;

  /// C(t_i) for control points c[j * stride].
  glm::dvec3 point(std::size_t i, const glm::dvec3* c, long stride) const;
  /// C(t) at any parameter (clamped to the drawn domain).
  glm::dvec3 pointAt(double t, const glm::dvec3* c, long stride) const;
  /// max_j |c_j − C(ḡ_j)|: how far the control polygon strays from the curve (O(h² κ) for span
  /// length h and curvature κ; what keeps an edited control point on the smoke).
  double netDeviation(const glm::dvec3* c, long stride) const;

 private:
  int mCount, mOrder;
  bool mConstant = false;
  std::vector<float> mKnots;
  std::vector<double> mGreville;
  std::vector<double> mParams;
  std::vector<BasisValues> mRows;
  BandedLu mLu;
};

}  // namespace plume
