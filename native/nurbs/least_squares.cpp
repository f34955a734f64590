#include "nurbs/least_squares.h"

#include "nurbs/knots.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace plume {
namespace {

void checkInputs(const std::vector<double>& params, int count, int order, double smoothing) {
  if (params.empty()) throw std::invalid_argument("least-squares fit needs at least one data point");
  if (order < kMinBlenderOrder || order > count || order > kMaxBlenderOrder) {
    std::ostringstream s;
    s << "least-squares fit: order must be in [2, min(6, count = " << count << ")] (got " << order
      << ")";
    throw std::invalid_argument(s.str());
  }
  if (!std::isfinite(smoothing) || smoothing < 0.0)
    throw std::invalid_argument("least-squares fit: smoothing must be finite and >= 0");
}

/// Number of different values among the parameters.
int distinctCount(std::vector<double> t) {
  std::sort(t.begin(), t.end());
  return int(std::unique(t.begin(), t.end()) - t.begin());
}

}  // namespace

CurveFitter::CurveFitter(const std::vector<double>& params, int count, int order, bool endpoint,
                         double smoothing)
    : mCount(count), mOrder(order), mParams(params), mLu(1, 0, 0) {
  checkInputs(params, count, order, smoothing);
  mKnots = blenderKnots(count, order, endpoint);
  mGreville = grevilleAbscissae(mKnots, count, order);
  const std::vector<float>& knots = mKnots;
  const KnotDomain dom = blenderDomain(knots, count, order);
  for (double t : params)
    if (!std::isfinite(t) || t < double(dom.start) - 1e-9 || t > double(dom.end) + 1e-9)
      throw std::invalid_argument("least-squares fit: parameters must lie in the drawn domain");
  mRows.reserve(params.size());
  for (double t : params) mRows.push_back(basisFunctions(knots, count, order, t));
  if (distinctCount(params) < 2) {
    mConstant = true;  // nothing tells the points apart: one constant curve through the mean
    return;
  }

  // Band of BᵀB (order − 1) and of the second differences (2), inside the matrix.
  const int band = std::min(count - 1, std::max(order - 1, count >= 3 ? 2 : 0));
  mLu = BandedLu(count, band, band);
  double traceData = 0.0;
  for (const BasisValues& b : mRows)
    for (int r = 0; r < order; ++r) {
      traceData += b.values[std::size_t(r)] * b.values[std::size_t(r)];
      for (int c = 0; c < order; ++c)
        mLu.add(b.first + r, b.first + c, b.values[std::size_t(r)] * b.values[std::size_t(c)]);
    }

  if (count >= 3 && smoothing > 0.0) {
    // Rows of D: h̄/Δ_{j-1}, −h̄/Δ_{j-1} − h̄/Δ_j, h̄/Δ_j on c_{j-1}, c_j, c_{j+1}.
    const std::vector<double>& g = mGreville;
    const double mean = (g.back() - g.front()) / double(count - 1);
    std::vector<glm::dvec3> rows(std::size_t(count - 2));
    double traceR = 0.0;
    for (int j = 1; j + 1 < count; ++j) {
      const double a = mean / std::max(g[std::size_t(j)] - g[std::size_t(j - 1)], 1e-12 * mean);
      const double b = mean / std::max(g[std::size_t(j + 1)] - g[std::size_t(j)], 1e-12 * mean);
      rows[std::size_t(j - 1)] = {a, -a - b, b};
      traceR += a * a + (a + b) * (a + b) + b * b;
    }
    const double lambda = smoothing * traceData / traceR;
    for (int j = 1; j + 1 < count; ++j) {
      const glm::dvec3& row = rows[std::size_t(j - 1)];
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) mLu.add(j - 1 + r, j - 1 + c, lambda * row[r] * row[c]);
    }
  }
  mLu.factor();
}

void CurveFitter::fit(const glm::dvec3* data, long stride, glm::dvec3* out, long outStride) const {
  const std::size_t m = mRows.size();
  if (mConstant) {
    glm::dvec3 mean(0.0);
    for (std::size_t i = 0; i < m; ++i) mean += data[long(i) * stride];
    mean /= double(m);
    for (int j = 0; j < mCount; ++j) out[long(j) * outStride] = mean;
    return;
  }
  std::vector<glm::dvec3> rhs(std::size_t(mCount), glm::dvec3(0.0));
  for (std::size_t i = 0; i < m; ++i) {
    const BasisValues& b = mRows[i];
    const glm::dvec3 q = data[long(i) * stride];
    for (int r = 0; r < mOrder; ++r) rhs[std::size_t(b.first + r)] += b.values[std::size_t(r)] * q;
  }
  mLu.solve(rhs);
  for (int j = 0; j < mCount; ++j) out[long(j) * outStride] = rhs[std::size_t(j)];
}

glm::dvec3 CurveFitter::point(std::size_t i, const glm::dvec3* c, long stride) const {
  const BasisValues& b = mRows.at(i);
  glm::dvec3 p(0.0);
  for (int r = 0; r < mOrder; ++r) p += b.values[std::size_t(r)] * c[long(b.first + r) * stride];
  return p;
}

glm::dvec3 CurveFitter::pointAt(double t, const glm::dvec3* c, long stride) const {
  const BasisValues b = basisFunctions(mKnots, mCount, mOrder, t);
  glm::dvec3 p(0.0);
  for (int r = 0; r < mOrder; ++r) p += b.values[std::size_t(r)] * c[long(b.first + r) * stride];
  return p;
}

double CurveFitter::netDeviation(const glm::dvec3* c, long stride) const {
  double worst = 0.0;
  for (int j = 0; j < mCount; ++j)
    worst = std::max(worst, glm::length(c[long(j) * stride] -
                                        pointAt(mGreville[std::size_t(j)], c, stride)));
  return worst;
}

}  // namespace plume
