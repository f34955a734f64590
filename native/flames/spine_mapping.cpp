/// \file spine_mapping.cpp
/// Spine polyline, arc length, rotation-minimizing frame and the Figure 4 mapping.

#include "flames/spine_mapping.h"

#include "flames/spine.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace plume {
namespace {

constexpr std::size_t kGroup = 4;  ///< polyline segments per bounding sphere in closest()
constexpr int kBucketsPerSegment = 2;  ///< arc-length buckets per polyline segment in locate()

}  // namespace

SpinePolyline spinePolyline(const Flame& flame, int perSegment) {
  const auto& p = flame.points;
  if (p.size() < 2) throw std::invalid_argument("a flame needs at least 2 spine points");
  perSegment = std::max(1, perSegment);
  SpinePolyline out;
  // The structure part's interpolating B-spline (§4.1), so the profile follows the very curve
  // the spine points were resampled on.
  const Spine spine = Spine::fit(p);
  const std::vector<double>& u = spine.knots();
  const std::vector<int>& source = spine.sourceIndices();
  for (std::size_t k = 0; k + 1 < u.size(); ++k) {
    const SpinePoint& a = p[std::size_t(source[k])];
    const SpinePoint& b = p[std::size_t(source[k + 1])];
    for (int j = 0; j < perSegment; ++j) {
      const double t = double(j) / perSegment;
      out.x.push_back(spine.evaluate(u[k] + t * (u[k + 1] - u[k])));
      out.v.push_back(a.v + (b.v - a.v) * t);
      out.age.push_back(a.age + (b.age - a.age) * t);
    }
  }
  // The tip (also the only point when all points coincide: then a zero-length spine).
  out.x.push_back(p.back().x);
  out.v.push_back(p.back().v);
  out.age.push_back(p.back().age);
  if (out.x.size() < 2) {
    out.x.push_back(p.back().x);
    out.v.push_back(p.back().v);
    out.age.push_back(p.back().age);
  }
  return out;
}

SpineFrame::SpineFrame(const Flame& flame, int perSegment) : mLine(spinePolyline(flame, perSegment)) {
  const std::size_t m = mLine.x.size();
  mArc.assign(m, 0.0);
  mT.assign(m, glm::dvec3(0.0, 0.0, 1.0));
  mN.assign(m, glm::dvec3(1.0, 0.0, 0.0));
  for (std::size_t k = 1; k < m; ++k) mArc[k] = mArc[k - 1] + glm::length(mLine.x[k] - mLine.x[k - 1]);
  // Tangents: central differences (one-sided at the ends); a degenerate spine keeps +Z.
  for (std::size_t k = 0; k < m; ++k) {
    const glm::dvec3 d = mLine.x[std::min(k + 1, m - 1)] - mLine.x[k > 0 ? k - 1 : 0];
    const double len = glm::length(d);
    mT[k] = len > 1e-12 ? d / len : (k > 0 ? mT[k - 1] : glm::dvec3(0.0, 0.0, 1.0));
  }
  // First normal: world X projected on the normal plane (world Y when T is along X), so a
  // straight vertical spine maps the profile's x to world x.
  glm::dvec3 ref = std::fabs(mT[0].x) < 0.9 ? glm::dvec3(1.0, 0.0, 0.0) : glm::dvec3(0.0, 1.0, 0.0);
  mN[0] = glm::normalize(ref - glm::dot(ref, mT[0]) * mT[0]);
  // Double reflection (Wang, Jüttler, Zheng & Liu 2008): rotation-minimizing normals.
  for (std::size_t k = 0; k + 1 < m; ++k) {
    const glm::dvec3 v1 = mLine.x[k + 1] - mLine.x[k];
    const double c1 = glm::dot(v1, v1);
    if (c1 < 1e-24) {
      mN[k + 1] = mN[k];
      continue;
    }
    const glm::dvec3 nL = mN[k] - (2.0 / c1) * glm::dot(v1, mN[k]) * v1;
    const glm::dvec3 tL = mT[k] - (2.0 / c1) * glm::dot(v1, mT[k]) * v1;
    const glm::dvec3 v2 = mT[k + 1] - tL;
    const double c2 = glm::dot(v2, v2);
    glm::dvec3 n = c2 < 1e-24 ? nL : nL - (2.0 / c2) * glm::dot(v2, nL) * v2;
    n -= glm::dot(n, mT[k + 1]) * mT[k + 1];
    mN[k + 1] = glm::normalize(n);
  }
  mLower = mUpper = mLine.x[0];
  for (const glm::dvec3& x : mLine.x) mLower = glm::min(mLower, x), mUpper = glm::max(mUpper, x);
  mDx.resize(m - 1), mDt.resize(m - 1), mDn.resize(m - 1), mLen2.resize(m - 1);
  for (std::size_t k = 0; k + 1 < m; ++k) {
    mDx[k] = mLine.x[k + 1] - mLine.x[k];
    mDt[k] = mT[k + 1] - mT[k];
    mDn[k] = mN[k + 1] - mN[k];
    mLen2[k] = glm::dot(mDx[k], mDx[k]);
  }
  // Arc-length buckets: bucket b starts at arc b / scale; it holds the last point at or below.
  const int buckets = kBucketsPerSegment * int(m - 1);
  mBucketScale = length() > 0.0 ? buckets / length() : 0.0;
  mBucket.assign(std::size_t(buckets), 0);
  for (int b = 0, k = 0; b < buckets && mBucketScale > 0.0; ++b) {
    const double start = b / mBucketScale;
    while (k + 1 < int(m) - 1 && mArc[std::size_t(k) + 1] <= start) ++k;
    mBucket[std::size_t(b)] = k;
  }
  // Bounding spheres of groups of segments (a group's segments lie in its points' hull).
  for (std::size_t g = 0; g + 1 < m; g += kGroup) {
    const std::size_t last = std::min(g + kGroup, m - 1);
    glm::dvec3 lo = mLine.x[g], hi = mLine.x[g];
    for (std::size_t k = g; k <= last; ++k) lo = glm::min(lo, mLine.x[k]), hi = glm::max(hi, mLine.x[k]);
    const glm::dvec3 centre = 0.5 * (lo + hi);
    double r = 0.0;
    for (std::size_t k = g; k <= last; ++k) r = std::max(r, glm::length(mLine.x[k] - centre));
    mGroups.emplace_back(centre, r);
  }
}

inline int SpineFrame::locate(double arc, double* f) const {
  // The last point k <= m - 2 with mArc[k] <= arc (0 if none): the bucket's start, then a step
  // or two either way (rounding at a bucket edge, several points in one bucket).
  const std::size_t m = mArc.size();
  const double b = std::clamp(arc * mBucketScale, 0.0, double(mBucket.size() - 1));
  std::size_t k = std::size_t(mBucket[std::size_t(b)]);
  while (k > 0 && mArc[k] > arc) --k;
  while (k + 2 < m && mArc[k + 1] <= arc) ++k;
  const double span = mArc[k + 1] - mArc[k];
  *f = span > 0.0 ? std::clamp((arc - mArc[k]) / span, 0.0, 1.0) : 0.0;
  return int(k);
}

inline void SpineFrame::frameAtArc(double arc, std::size_t k, double f, Point* p) const {
  p->t = glm::normalize(mT[k] + f * mDt[k]);
  const glm::dvec3 nn = mN[k] + f * mDn[k];
  p->n = glm::normalize(nn - glm::dot(nn, p->t) * p->t);
  p->b = glm::cross(p->t, p->n);
  if (arc < 0.0) {
    p->c = mLine.x.front() + arc * mT.front();
  } else if (arc > length()) {
    p->c = mLine.x.back() + (arc - length()) * mT.back();
  } else {
    p->c = mLine.x[k] + f * mDx[k];
  }
}

SpineFrame::Point SpineFrame::at(double s) const {
  const double arc = s * length();
  double f;
  const std::size_t k = std::size_t(locate(arc, &f));
  Point p;
  frameAtArc(arc, k, f, &p);
  // locate() clamps f to [0, 1], so velocity and age stop at the ends.
  p.v = mLine.v[k] + f * (mLine.v[k + 1] - mLine.v[k]);
  p.age = mLine.age[k] + f * (mLine.age[k + 1] - mLine.age[k]);
  return p;
}

void SpineFrame::motionAt(double s, glm::dvec3* v, double* age) const {
  double f;
  const std::size_t k = std::size_t(locate(s * length(), &f));
  *v = mLine.v[k] + f * (mLine.v[k + 1] - mLine.v[k]);
  *age = mLine.age[k] + f * (mLine.age[k + 1] - mLine.age[k]);
}

void SpineFrame::frameAt(double s, glm::dvec3* c, glm::dvec3* t, glm::dvec3* n, glm::dvec3* b) const {
  const Point p = at(s);
  *c = p.c, *t = p.t, *n = p.n, *b = p.b;
}

glm::dvec3 SpineFrame::map(const glm::dvec3& p, double aspect, double radius) const {
  const double arc = p.z / aspect * length();
  double f;
  const std::size_t k = std::size_t(locate(arc, &f));
  Point q;
  frameAtArc(arc, k, f, &q);
  return q.c + radius * (p.x * q.n + p.y * q.b);
}

glm::dvec3 SpineFrame::velocityAt(double s) const { return at(std::clamp(s, 0.0, 1.0)).v; }

double SpineFrame::ageAt(double s) const { return at(std::clamp(s, 0.0, 1.0)).age; }

double SpineFrame::closest(const glm::dvec3& x, double* distance, double within) const {
  // Squared distances, one square root at the end; the box test rejects far points at once.
  if (within > 0.0) {
    const glm::dvec3 lo = mLower - glm::dvec3(within), hi = mUpper + glm::dvec3(within);
    if (x.x < lo.x || x.y < lo.y || x.z < lo.z || x.x > hi.x || x.y > hi.y || x.z > hi.z) {
      *distance = std::numeric_limits<double>::max();
      return -1.0;
    }
  }
  // With `within`, segments farther than it are never the answer (the result is then −1), so the
  // search starts at within² (a hair more: the final test below decides). A group of segments
  // whose bounding sphere is farther than the best distance so far (with a relative margin far
  // above rounding) cannot hold a strictly closer segment: skipped. Segments are visited in order and
  // only a strictly closer one replaces the best, so the answer is the full scan's.
  const double start = within > 0.0 ? within * within * (1.0 + 1e-9) : std::numeric_limits<double>::max();
  double best = start, bestT = 0.0;
  double reach = std::sqrt(best) * (1.0 + 1e-9);  // the best distance so far, rounded up
  std::size_t bestK = 0;
  bool found = false;
  const std::size_t segments = mLine.x.size() - 1;
  for (std::size_t g = 0; g < mGroups.size(); ++g) {
    const glm::dvec4& sphere = mGroups[g];
    const glm::dvec3 toCentre = x - glm::dvec3(sphere);
    if (glm::dot(toCentre, toCentre) > (sphere.w + reach) * (sphere.w + reach)) continue;
    for (std::size_t k = g * kGroup; k < std::min(segments, (g + 1) * kGroup); ++k) {
      const glm::dvec3 &a = mLine.x[k], &ab = mDx[k], ax = x - a;
      const double len2 = mLen2[k];
      const double t = len2 > 0.0 ? std::clamp(glm::dot(ax, ab) / len2, 0.0, 1.0) : 0.0;
      const glm::dvec3 d = ax - t * ab;
      const double d2 = glm::dot(d, d);
      if (d2 < best) best = d2, bestT = t, bestK = k, found = true, reach = std::sqrt(d2) * (1.0 + 1e-9);
    }
  }
  if (!found) {
    *distance = std::numeric_limits<double>::max();
    return -1.0;
  }
  *distance = std::sqrt(best);
  if (within > 0.0 && *distance > within) return -1.0;
  const double arc = mArc[bestK] + bestT * (mArc[bestK + 1] - mArc[bestK]);
  return length() > 0.0 ? arc / length() : 0.0;
}

}  // namespace plume
