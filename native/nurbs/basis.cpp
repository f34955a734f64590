#include "nurbs/basis.h"

#include <algorithm>
#include <stdexcept>

namespace plume {

int findSpan(const std::vector<float>& knots, int pointCount, int order, double t) {
  if (order < 1 || pointCount < order || knots.size() != std::size_t(pointCount + order))
    throw std::invalid_argument("findSpan: knots must have point count + order values");
  const int p = order - 1;
  const double lo = knots[std::size_t(p)], hi = knots[std::size_t(pointCount)];
  t = std::clamp(t, lo, hi);
  if (t >= hi) {
    // The end of the domain belongs to the last non-empty span (basisNurb's closed interval).
    int s = pointCount - 1;
    while (s > p && knots[std::size_t(s)] == knots[std::size_t(s + 1)]) --s;
    return s;
  }
  // Largest s in [p, n-1] with knots[s] <= t.
  int low = p, high = pointCount;
  while (high - low > 1) {
    const int mid = (low + high) / 2;
    if (t < double(knots[std::size_t(mid)]))
      high = mid;
    else
      low = mid;
  }
  return low;
}

namespace {

/// The NURBS Book A2.2: the degree-`degree` basis functions non-zero on span s at t.
void basisOfDegree(const std::vector<float>& U, int s, int degree, double t, double* N) {
  double left[8], right[8];
  N[0] = 1.0;
  for (int j = 1; j <= degree; ++j) {
    left[j] = t - double(U[std::size_t(s + 1 - j)]);
    right[j] = double(U[std::size_t(s + j)]) - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      const double denom = right[r + 1] + left[j - r];
      const double temp = denom != 0.0 ? N[r] / denom : 0.0;
      N[r] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    N[j] = saved;
  }
}

}  // namespace

BasisValues basisFunctions(const std::vector<float>& knots, int pointCount, int order, double t,
                           bool withDerivatives) {
  const int s = findSpan(knots, pointCount, order, t);
  const int p = order - 1;
  t = std::clamp(t, double(knots[std::size_t(p)]), double(knots[std::size_t(pointCount)]));
  BasisValues b;
  b.first = s - p;
  b.values.assign(std::size_t(order), 0.0);
  basisOfDegree(knots, s, p, t, b.values.data());
  if (withDerivatives) {
    b.derivatives.assign(std::size_t(order), 0.0);
    if (p > 0) {
      // dN_{i,p}/dt = p N_{i,p-1} / (t_{i+p} - t_i) - p N_{i+1,p-1} / (t_{i+p+1} - t_{i+1}),
      // with the degree p-1 functions N_{s-p+1..s} of the same span.
      double lower[8] = {0.0};
      basisOfDegree(knots, s, p - 1, t, lower);
      auto lowerAt = [&](int i) { return (i >= s - p + 1 && i <= s) ? lower[i - (s - p + 1)] : 0.0; };
      for (int r = 0; r < order; ++r) {
        const int i = s - p + r;
        const double d0 = double(knots[std::size_t(i + p)]) - double(knots[std::size_t(i)]);
        const double d1 = double(knots[std::size_t(i + p + 1)]) - double(knots[std::size_t(i + 1)]);
        double d = 0.0;
        if (d0 != 0.0) d += p * lowerAt(i) / d0;
        if (d1 != 0.0) d -= p * lowerAt(i + 1) / d1;
        b.derivatives[std::size_t(r)] = d;
      }
    }
  }
  return b;
}

}  // namespace plume
