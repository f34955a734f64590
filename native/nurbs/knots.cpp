#include "nurbs/knots.h"

#include <sstream>
#include <stdexcept>

namespace plume {
namespace {

void checkDirection(int pointCount, int order) {
  if (pointCount < 1) {
    std::ostringstream s;
    s << "point count must be at least 1 (got " << pointCount << ")";
    throw std::invalid_argument(s.str());
  }
  if (order < 1 || order > pointCount || order > kMaxBlenderOrder) {
    std::ostringstream s;
    s << "order must be in [1, min(" << kMaxBlenderOrder << ", point count = " << pointCount
      << ")] (got " << order << ")";
    throw std::invalid_argument(s.str());
  }
}

}  // namespace

std::vector<float> blenderKnots(int pointCount, int order, bool endpoint) {
  checkDirection(pointCount, order);
  const int count = pointCount + order;
  std::vector<float> knots(std::size_t(count), 0.f);
  if (endpoint) {
    // calcknots(), case CU_NURB_ENDPOINT: the value grows by one after knot a (1-based) for
    // order <= a <= pnts, so knots 0..order-1 are 0 and the last `order` share one value.
    float k = 0.f;
    for (int a = 1; a <= count; ++a) {
      knots[std::size_t(a - 1)] = k;
      if (a >= order && a <= pointCount) k += 1.f;
    }
  } else {
    // calcknots(), default (uniform): knots[a] = a.
    for (int a = 0; a < count; ++a) knots[std::size_t(a)] = float(a);
  }
  return knots;
}

KnotDomain blenderDomain(const std::vector<float>& knots, int pointCount, int order) {
  checkDirection(pointCount, order);
  if (knots.size() != std::size_t(pointCount + order))
    throw std::invalid_argument("knots must have point count + order values");
  return {knots[std::size_t(order - 1)], knots[std::size_t(pointCount)]};
}

std::vector<float> blenderSamples(int pointCount, int order, bool endpoint, int resolution) {
  if (resolution < 1 || resolution > kMaxBlenderResolution) {
    std::ostringstream s;
    s << "resolution must be in [1, " << kMaxBlenderResolution << "] (got " << resolution << ")";
    throw std::invalid_argument(s.str());
  }
  const std::vector<float> knots = blenderKnots(pointCount, order, endpoint);
  const KnotDomain d = blenderDomain(knots, pointCount, order);
  const int total = pointCount * resolution;
  std::vector<float> samples(static_cast<std::size_t>(total));
  // BKE_nurb_makeFaces: ustep = (uend - ustart) / (totu - 1); u = ustart; u += ustep. Kept in
  // float and accumulated, exactly as Blender does, so the last sample may miss `end` by an ulp.
  const float step = total > 1 ? (d.end - d.start) / float(total - 1) : 0.f;
  float u = d.start;
  for (int s = 0; s < total; ++s) {
    samples[std::size_t(s)] = u;
    u += step;
  }
  return samples;
}

std::vector<double> grevilleAbscissae(const std::vector<float>& knots, int pointCount, int order) {
  checkDirection(pointCount, order);
  if (knots.size() != std::size_t(pointCount + order))
    throw std::invalid_argument("knots must have point count + order values");
  std::vector<double> g(static_cast<std::size_t>(pointCount));
  for (int i = 0; i < pointCount; ++i) {
    if (order == 1) {
      g[std::size_t(i)] = 0.5 * (double(knots[std::size_t(i)]) + double(knots[std::size_t(i + 1)]));
      continue;
    }
    double sum = 0.0;
    for (int j = i + 1; j <= i + order - 1; ++j) sum += double(knots[std::size_t(j)]);
    g[std::size_t(i)] = sum / double(order - 1);
  }
  return g;
}

std::vector<double> interpolationParameters(int pointCount, int order, bool endpoint) {
  const std::vector<float> knots = blenderKnots(pointCount, order, endpoint);
  const KnotDomain d = blenderDomain(knots, pointCount, order);
  const double start = d.start, end = d.end;
  std::vector<double> g = grevilleAbscissae(knots, pointCount, order);
  const int n = pointCount;
  if (n == 1) return {0.5 * (start + end)};
  // Greville points outside the drawn interval (uniform knots only: ḡ_0 = k/2 < k - 1).
  int left = 0, right = 0;
  for (double x : g) {
    if (x < start) ++left;
    if (x > end) ++right;
  }
  std::vector<double> tau(g);
  if (n >= left + right + 3) {
    // Keep the Greville points inside; the outer ones and the first/last inside one are spread
    // evenly from the domain's end to the next Greville point. Spreading all of them evenly
    // instead would drift the parameters across the knot spans and, for long streaklines, pass
    // through half-span offsets where the cubic collocation matrix is nearly singular.
    const double anchorLeft = g[std::size_t(left + 1)];
    for (int j = 0; j <= left; ++j)
      tau[std::size_t(j)] = start + (anchorLeft - start) * double(j) / double(left + 1);
    const double anchorRight = g[std::size_t(n - 2 - right)];
    for (int j = 0; j <= right; ++j)
      tau[std::size_t(n - 1 - j)] = end - (end - anchorRight) * double(j) / double(right + 1);
  } else {
    // Few points (n ≤ order with uniform knots): evenly over the drawn interval.
    for (int i = 0; i < n; ++i) tau[std::size_t(i)] = start + (end - start) * double(i) / double(n - 1);
  }
  // Exact ends: the first and last particle sit on the boundary of the drawn surface.
  tau.front() = start;
  tau.back() = end;
  return tau;
}

}  // namespace plume
