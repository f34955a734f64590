/// \file spine.cpp
/// Interpolating cubic B-spline spines, arc length and re-sampling (§4.1).

#include "flames/spine.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace plume {
namespace {

constexpr int kSub = 4;  // Gauss–Legendre sub-intervals per span

// 5-point Gauss–Legendre nodes on [-1, 1] and weights.
constexpr double kGaussX[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                               0.9061798459386640};
constexpr double kGaussW[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                               0.4786286704993665, 0.2369268850561891};

}  // namespace

Spine::Spine(const std::vector<glm::dvec3>& points) {
  if (points.empty()) throw std::invalid_argument("a spine needs at least 1 point");
  // Scale of the curve, so that "coincident" is relative to its size (1e-12 of the extent).
  double extent = 0.0;
  for (const glm::dvec3& p : points) extent = std::max(extent, glm::length(p - points.front()));
  const double eps = 1e-12 * std::max(extent, 1e-300);
  for (int k = 0; k < int(points.size()); ++k) {
    const glm::dvec3& p = points[std::size_t(k)];
    if (!mPoints.empty() && glm::length(p - mPoints.back()) <= eps) {
      // A repeated last point replaces its twin so that the curve still ends exactly on it.
      if (k == int(points.size()) - 1 && mPoints.size() > 1) {
        mPoints.back() = p;
        mSource.back() = k;
      }
      continue;
    }
    mKnots.push_back(mPoints.empty() ? 0.0 : mKnots.back() + glm::length(p - mPoints.back()));
    mPoints.push_back(p);
    mSource.push_back(k);
  }
  // After replacing a twin, the last knot is re-measured from its predecessor.
  const std::size_t m = mPoints.size();
  if (m > 1) mKnots[m - 1] = mKnots[m - 2] + glm::length(mPoints[m - 1] - mPoints[m - 2]);

  // Natural cubic spline: h_{k-1} M_{k-1} + 2(h_{k-1} + h_k) M_k + h_k M_{k+1} = 6 (Δ_k − Δ_{k-1}),
  // M_0 = M_{m-1} = 0, solved by the Thomas algorithm (diagonally dominant, stable).
  mSecond.assign(m, glm::dvec3(0.0));
  if (m > 2) {
    std::vector<double> c(m, 0.0);
    std::vector<glm::dvec3> d(m, glm::dvec3(0.0));
    for (std::size_t k = 1; k + 1 < m; ++k) {
      const double h0 = mKnots[k] - mKnots[k - 1], h1 = mKnots[k + 1] - mKnots[k];
      const glm::dvec3 rhs =
          6.0 * ((mPoints[k + 1] - mPoints[k]) / h1 - (mPoints[k] - mPoints[k - 1]) / h0);
      const double diag = 2.0 * (h0 + h1) - h0 * c[k - 1];
      c[k] = h1 / diag;
      d[k] = (rhs - h0 * d[k - 1]) / diag;
    }
    for (std::size_t k = m - 2; k >= 1; --k) mSecond[k] = d[k] - c[k] * mSecond[k + 1];
  }

  mTable.assign(std::size_t(std::max<int>(0, int(m) - 1) * kSub) + 1, 0.0);
  for (int span = 0; span + 1 < int(m); ++span) {
    const double h = mKnots[std::size_t(span) + 1] - mKnots[std::size_t(span)];
    for (int q = 0; q < kSub; ++q) {
      const std::size_t at = std::size_t(span * kSub + q);
      mTable[at + 1] = mTable[at] + spanArc(span, h * q / kSub, h * (q + 1) / kSub);
    }
  }
}

Spine Spine::fit(const std::vector<SpinePoint>& points) {
  std::vector<glm::dvec3> x(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) x[k] = points[k].x;
  return Spine(x);
}

int Spine::spanOf(double u) const {
  const int spans = int(mKnots.size()) - 1;
  const int k = int(std::upper_bound(mKnots.begin(), mKnots.end(), u) - mKnots.begin()) - 1;
  return std::clamp(k, 0, std::max(spans - 1, 0));
}

glm::dvec3 Spine::evaluate(double u) const {
  if (mPoints.size() < 2) return mPoints.front();
  u = std::clamp(u, 0.0, parameterEnd());
  const int k = spanOf(u);
  const std::size_t a = std::size_t(k), b = a + 1;
  const double h = mKnots[b] - mKnots[a], t = u - mKnots[a];
  return mPoints[a] + t * (spanSlope(k) + t * (0.5 * mSecond[a] + t * (mSecond[b] - mSecond[a]) / (6.0 * h)));
}

glm::dvec3 Spine::spanSlope(int span) const {
  const std::size_t a = std::size_t(span), b = a + 1;
  const double h = mKnots[b] - mKnots[a];
  return (mPoints[b] - mPoints[a]) / h - h * (2.0 * mSecond[a] + mSecond[b]) / 6.0;
}

glm::dvec3 Spine::spanDerivative(int span, double t) const {
  const std::size_t a = std::size_t(span), b = a + 1;
  const double h = mKnots[b] - mKnots[a];
  return spanSlope(span) + t * (mSecond[a] + t * (mSecond[b] - mSecond[a]) / (2.0 * h));
}

glm::dvec3 Spine::derivative(double u) const {
  if (mPoints.size() < 2) return glm::dvec3(0.0);
  u = std::clamp(u, 0.0, parameterEnd());
  const int k = spanOf(u);
  return spanDerivative(k, u - mKnots[std::size_t(k)]);
}

glm::dvec3 Spine::tangent(double u) const {
  if (mPoints.size() < 2) return glm::dvec3(0.0, 0.0, 1.0);
  const glm::dvec3 d = derivative(u);
  const double len = glm::length(d);
  if (len > 1e-12) return d / len;
  const int k = spanOf(std::clamp(u, 0.0, parameterEnd()));
  return glm::normalize(mPoints[std::size_t(k) + 1] - mPoints[std::size_t(k)]);
}

double Spine::spanArc(int span, double t0, double t1) const {
  const double u0 = mKnots[std::size_t(span)];
  const double half = 0.5 * (t1 - t0), mid = u0 + 0.5 * (t0 + t1);
  double sum = 0.0;
  for (int g = 0; g < 5; ++g) {
    // Evaluated inside this span (not via spanOf) so a node on a knot uses the right cubic.
    sum += kGaussW[g] * glm::length(spanDerivative(span, mid + half * kGaussX[g] - u0));
  }
  return half * sum;
}

double Spine::arcLength(double u) const {
  if (mPoints.size() < 2) return 0.0;
  u = std::clamp(u, 0.0, parameterEnd());
  const int k = spanOf(u);
  const double h = mKnots[std::size_t(k) + 1] - mKnots[std::size_t(k)], t = u - mKnots[std::size_t(k)];
  const int q = std::min(kSub - 1, int(t / h * kSub));
  const double tq = h * q / kSub;
  return mTable[std::size_t(k * kSub + q)] + spanArc(k, tq, t);
}

double Spine::parameterAt(double s) const {
  if (mPoints.size() < 2) return 0.0;
  s = std::clamp(s, 0.0, length());
  // The sub-interval holding s, then Newton on s(u) − s inside it (s'(u) = |C'(u)|), kept in the
  // bracket by bisection when a step leaves it.
  const int entry = std::clamp(
      int(std::upper_bound(mTable.begin(), mTable.end(), s) - mTable.begin()) - 1, 0, int(mTable.size()) - 2);
  const int span = entry / kSub, q = entry % kSub;
  const double h = mKnots[std::size_t(span) + 1] - mKnots[std::size_t(span)];
  const double tq = h * q / kSub;
  double lo = tq, hi = h * (q + 1) / kSub;
  const double s0 = mTable[std::size_t(entry)], ds = mTable[std::size_t(entry) + 1] - s0;
  double t = ds > 0.0 ? lo + (hi - lo) * (s - s0) / ds : lo;
  const double tol = 1e-13 * std::max(length(), 1e-300);
  for (int it = 0; it < 50; ++it) {
    const double f = s0 + spanArc(span, tq, t) - s;
    if (std::abs(f) <= tol) break;
    if (f > 0.0) hi = t; else lo = t;
    const double speed = glm::length(spanDerivative(span, t));
    double next = speed > 0.0 ? t - f / speed : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    t = next;
  }
  return mKnots[std::size_t(span)] + t;
}

std::vector<SpinePoint> resampleSpine(const Spine& spine, const std::vector<SpinePoint>& points,
                                      double s0, double s1, int count) {
  if (count < 2) throw std::invalid_argument("re-sampling needs at least 2 points");
  const double length = spine.length();
  s0 = std::clamp(s0, 0.0, length);
  s1 = std::clamp(s1, s0, length);
  const std::vector<double>& knots = spine.knots();
  const std::vector<int>& source = spine.sourceIndices();
  std::vector<SpinePoint> out(static_cast<std::size_t>(count));
  for (int j = 0; j < count; ++j) {
    SpinePoint& p = out[std::size_t(j)];
    if (length <= 0.0 || knots.size() < 2) {
      // Zero-length curve: every point on the base, attributes from the ends.
      const double a = double(j) / double(count - 1);
      p = points.front();
      p.age = (1.0 - a) * points.front().age + a * points.back().age;
      p.v = (1.0 - a) * points.front().v + a * points.back().v;
      continue;
    }
    const double s = (j == count - 1) ? s1 : s0 + (s1 - s0) * double(j) / double(count - 1);
    if ((j == 0 && s <= 0.0) || (j == count - 1 && s >= length)) {
      p = (s <= 0.0) ? points[std::size_t(source.front())] : points[std::size_t(source.back())];
      continue;
    }
    const double u = spine.parameterAt(s);
    const int k = std::clamp(int(std::upper_bound(knots.begin(), knots.end(), u) - knots.begin()) - 1, 0,
                             int(knots.size()) - 2);
    const double a = (u - knots[std::size_t(k)]) / (knots[std::size_t(k) + 1] - knots[std::size_t(k)]);
    const SpinePoint& p0 = points[std::size_t(source[std::size_t(k)])];
    const SpinePoint& p1 = points[std::size_t(source[std::size_t(k) + 1])];
    p.x = spine.evaluate(u);
    p.v = (1.0 - a) * p0.v + a * p1.v;
    p.age = (1.0 - a) * p0.age + a * p1.age;
  }
  return out;
}

std::vector<SpinePoint> resampleSpine(const std::vector<SpinePoint>& points, int count) {
  const Spine spine = Spine::fit(points);
  return resampleSpine(spine, points, 0.0, spine.length(), count);
}

double polylineLength(const std::vector<SpinePoint>& points) {
  double sum = 0.0;
  for (std::size_t k = 1; k < points.size(); ++k) sum += glm::length(points[k].x - points[k - 1].x);
  return sum;
}

}  // namespace plume
