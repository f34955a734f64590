/// \file breakaway.cpp
/// The statistical flicker and separation process (§4.3).

#include "flames/breakaway.h"

#include "flames/spine.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace plume {
namespace {

/// Arc length of every input point along the curve through them.
std::vector<double> pointArcLengths(const Spine& spine, std::size_t count) {
  std::vector<double> s(count, 0.0);
  const std::vector<double>& knots = spine.knots();
  const std::vector<int>& source = spine.sourceIndices();
  // Merged duplicates take the arc length of the knot kept before them.
  std::size_t k = 0;
  for (std::size_t i = 0; i < count; ++i) {
    while (k + 1 < source.size() && std::size_t(source[k + 1]) <= i) ++k;
    s[i] = spine.arcLength(knots[k]);
  }
  return s;
}

}  // namespace

double drawWaitingTime(double frequency, Rng& rng) {
  if (!(frequency > 0.0)) return std::numeric_limits<double>::infinity();
  return -std::log(1.0 - rng.uniform()) / frequency;  // 1 − U in (0, 1]: finite
}

double drawSplitHeight(const FlameHeights& heights, Rng& rng) {
  const double span = heights.intermittent - heights.persistent;
  const double h = heights.persistent + 0.5 * span + 0.25 * span * rng.normal();
  const double lo = std::max(heights.persistent, 0.01 * heights.intermittent);
  return std::clamp(h, lo, heights.intermittent);
}

double drawLifespan(double lifespanScale, Rng& rng) {
  const double i = rng.uniform();
  return lifespanScale * i * i * i;
}

BreakawayDecision testBreakaway(double length, const FlameHeights& heights, double frequency, double dt,
                                double& budget, Rng& rng) {
  BreakawayDecision d;
  if (!(length > heights.intermittent)) return d;
  d.eligible = true;
  budget -= dt;
  if (length > heights.max) {
    d.split = d.forced = true;
  } else if (budget <= 0.0) {
    d.split = true;
    budget += drawWaitingTime(frequency, rng);
  }
  if (d.split) d.height = std::min(drawSplitHeight(heights, rng), length);
  return d;
}

void splitSpine(const std::vector<SpinePoint>& points, double height, int lowerCount,
                std::vector<SpinePoint>& lower, std::vector<SpinePoint>& upper) {
  const Spine spine = Spine::fit(points);
  const std::vector<double> s = pointArcLengths(spine, points.size());
  const int above = int(std::count_if(s.begin(), s.end(), [&](double v) { return v > height; }));
  const int below = int(std::count_if(s.begin(), s.end(), [&](double v) { return v < height; }));
  lower = resampleSpine(spine, points, 0.0, height, lowerCount > 0 ? lowerCount : std::max(2, below + 1));
  upper = resampleSpine(spine, points, height, spine.length(), std::max(2, above + 1));
}

}  // namespace plume
