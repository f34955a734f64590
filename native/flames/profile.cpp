/// \file profile.cpp
/// Library profiles (Figure 3, read off the figure) and artist curves, normalized.

#include "flames/profile.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace plume {

FlameProfile::FlameProfile(std::vector<glm::dvec2> sr, double aspect)
    : mPoints(std::move(sr)), mAspect(aspect) {
  // Closed to the axis at both ends: a torch's wide base gets a disc, so "inside" is defined
  // (merging, §4.5) and the closest point of eq. 4 below the base is on that disc.
  if (mPoints.front().y > 0.0) mMeridian.push_back({0.0, 0.0});
  for (const glm::dvec2& p : mPoints) mMeridian.push_back({p.y, p.x * mAspect});
  if (mPoints.back().y > 0.0) mMeridian.push_back({0.0, mAspect});
}

FlameProfile FlameProfile::library(ProfileShape shape) {
  // (s, r) read off Figure 3: the candle a teardrop widest at a third of its height, the torch
  // wide at the base with a long tongue, the campfire widest at the base and tapering.
  switch (shape) {
    case ProfileShape::Candle:
      return FlameProfile({{0.0, 0.0}, {0.04, 0.5}, {0.12, 0.85}, {0.25, 1.0}, {0.4, 0.95},
                           {0.55, 0.78}, {0.7, 0.55}, {0.85, 0.28}, {0.95, 0.1}, {1.0, 0.0}},
                          3.5);
    case ProfileShape::Torch:
      return FlameProfile({{0.0, 0.6}, {0.08, 0.92}, {0.2, 1.0}, {0.35, 0.9}, {0.5, 0.7},
                           {0.65, 0.48}, {0.8, 0.27}, {0.92, 0.1}, {1.0, 0.0}},
                          3.0);
    case ProfileShape::Campfire:
      return FlameProfile({{0.0, 1.0}, {0.12, 0.97}, {0.25, 0.85}, {0.4, 0.66}, {0.55, 0.48},
                           {0.7, 0.31}, {0.85, 0.15}, {1.0, 0.0}},
                          2.5);
    case ProfileShape::Custom: break;
  }
  throw std::invalid_argument("profile must be candle, torch or campfire for a library profile");
}

FlameProfile FlameProfile::fromCurve(const std::vector<glm::dvec2>& points) {
  if (points.size() < 2)
    throw std::invalid_argument("profile curve must have at least 2 points (got " +
                                std::to_string(points.size()) + ")");
  double width = 0.0;
  for (std::size_t n = 0; n < points.size(); ++n) {
    if (!std::isfinite(points[n].x) || !std::isfinite(points[n].y))
      throw std::invalid_argument("profile curve point " + std::to_string(n) + " is not finite");
    if (n > 0 && points[n].y < points[n - 1].y)
      throw std::invalid_argument("profile curve heights must not decrease from base to tip (point " +
                                  std::to_string(n) + ")");
    width = std::max(width, std::fabs(points[n].x));
  }
  const double z0 = points.front().y, height = points.back().y - z0;
  if (!(height > 0.0)) throw std::invalid_argument("profile curve must have a height > 0");
  if (!(width > 0.0)) throw std::invalid_argument("profile curve must have a radius > 0 somewhere");
  std::vector<glm::dvec2> sr;
  for (const glm::dvec2& p : points) sr.push_back({(p.y - z0) / height, std::fabs(p.x) / width});
  return FlameProfile(std::move(sr), height / width);
}

double FlameProfile::radius(double s) const {
  if (!(s >= 0.0 && s <= 1.0)) return 0.0;
  auto it = std::upper_bound(mPoints.begin(), mPoints.end(), s,
                             [](double v, const glm::dvec2& p) { return v < p.x; });
  if (it == mPoints.begin()) return mPoints.front().y;
  if (it == mPoints.end()) return mPoints.back().y;
  const glm::dvec2 a = *(it - 1), b = *it;
  const double span = b.x - a.x;
  return span > 0.0 ? a.y + (b.y - a.y) * (s - a.x) / span : std::max(a.y, b.y);
}

ProfileShape profileShapeFromName(const std::string& name) {
  if (name == "candle") return ProfileShape::Candle;
  if (name == "torch") return ProfileShape::Torch;
  if (name == "campfire") return ProfileShape::Campfire;
  throw std::invalid_argument("profile must be one of candle, torch, campfire (got '" + name + "')");
}

}  // namespace plume
