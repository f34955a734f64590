/// \file merging.cpp
/// Neighbour boxes and the inside test of §4.5.

#include "flames/merging.h"

#include <algorithm>
#include <cmath>

namespace plume {

MergeVolume mergeVolume(const SpineFrame& spine, const FlameProfile& profile, double radius) {
  MergeVolume v;
  v.spine = &spine;
  v.profile = &profile;
  v.radius = radius;
  v.lower = spine.lower() - glm::dvec3(radius);
  v.upper = spine.upper() + glm::dvec3(radius);
  const std::vector<glm::dvec3>& points = spine.points();
  v.chordStart = points.front();
  v.chord = points.back() - points.front();
  v.chordLength2 = glm::dot(v.chord, v.chord);
  // The distance to a segment is convex, so along each polyline segment it peaks at an end.
  double deviation = 0.0;
  for (const glm::dvec3& p : points) deviation = std::max(deviation, std::sqrt(chordDistance2(v, p)));
  // Margin far above rounding: the capsule may only ever hold more than the spine's R-tube.
  const double capsule = (radius + deviation) * (1.0 + 1e-6) + 1e-12;
  v.capsule2 = capsule * capsule;
  return v;
}

double chordDistance2(const MergeVolume& g, const glm::dvec3& x) {
  const glm::dvec3 ax = x - g.chordStart;
  const double t = g.chordLength2 > 0.0 ? std::clamp(glm::dot(ax, g.chord) / g.chordLength2, 0.0, 1.0) : 0.0;
  const glm::dvec3 d = ax - t * g.chord;
  return glm::dot(d, d);
}

bool insideFlame(const MergeVolume& g, const glm::dvec3& x) {
  if (x.x < g.lower.x || x.y < g.lower.y || x.z < g.lower.z || x.x > g.upper.x || x.y > g.upper.y ||
      x.z > g.upper.z)
    return false;
  // Outside the capsule: farther than R from every point of the spine, so outside (below).
  if (chordDistance2(g, x) > g.capsule2) return false;
  double distance;
  // Farther than R from the spine is outside (the widest radius is 1).
  const double s = g.spine->closest(x, &distance, g.radius);
  if (s < 0.0) return false;
  // At the ends the closest point is the end point: inside only when x is level with it.
  if (s <= 0.0 || s >= 1.0) {
    glm::dvec3 c, t, n, b;
    g.spine->frameAt(s <= 0.0 ? 0.0 : 1.0, &c, &t, &n, &b);
    const double along = glm::dot(x - c, t);
    if (s <= 0.0 ? along < 0.0 : along > 0.0) return false;
  }
  return distance <= g.radius * g.profile->radius(s);
}

std::vector<std::vector<int>> mergeNeighbours(const std::vector<MergeVolume>& volumes) {
  std::vector<std::vector<int>> out(volumes.size());
  for (std::size_t a = 0; a < volumes.size(); ++a)
    for (std::size_t b = 0; b < volumes.size(); ++b) {
      if (a == b) continue;
      const MergeVolume &p = volumes[a], &q = volumes[b];
      const glm::dvec3 lo = p.lower - glm::dvec3(p.reach), hi = p.upper + glm::dvec3(p.reach);
      if (lo.x <= q.upper.x && q.lower.x <= hi.x && lo.y <= q.upper.y && q.lower.y <= hi.y && lo.z <= q.upper.z &&
          q.lower.z <= hi.z)
        out[a].push_back(int(b));
    }
  return out;
}

bool mergedAway(const std::vector<MergeVolume>& volumes, const std::vector<int>& neighbours,
                const glm::dvec3& x, bool insideOwn) {
  if (insideOwn) return false;
  for (int g : neighbours)
    if (insideFlame(volumes[std::size_t(g)], x)) return true;
  return false;
}

}  // namespace plume
