#include "streak/streak_group.h"

#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace plume {

StreakGroup::StreakGroup(SharedStreakFrames frames, std::vector<int> sourceIds)
    : mFrames(std::move(frames)), mSourceIds(std::move(sourceIds)) {
  if (!mFrames) throw std::invalid_argument("no streak frames given");
  const std::size_t n = mSourceIds.size();
  for (std::size_t t = 0; t < mFrames->size(); ++t) {
    const StreakFrame& f = (*mFrames)[t];
    // Only counts and positions are read here (density and outside may be left empty).
    std::size_t total = 0;
    for (std::size_t s = 0; s < f.counts.size(); ++s) {
      if (f.counts[s] < 0)
        throw std::invalid_argument("streak frame " + std::to_string(t) + ": counts[" +
                                    std::to_string(s) + "] is negative");
      total += std::size_t(f.counts[s]);
    }
    if (f.positions.size() != total)
      throw std::invalid_argument("streak frame " + std::to_string(t) + ": counts sum to " +
                                  std::to_string(total) + " particles but there are " +
                                  std::to_string(f.positions.size()) + " positions");
    const std::vector<std::size_t> offsets = f.offsets();
    int count = 0;
    for (std::size_t a = 0; a < n; ++a) {
      const int id = mSourceIds[a];
      if (id < 0 || id >= f.sourceCount())
        throw std::invalid_argument("source ID " + std::to_string(id) + " is not in frame " +
                                    std::to_string(t) + " (" + std::to_string(f.sourceCount()) +
                                    " sources)");
      const int c = f.counts[std::size_t(id)];
      if (a == 0) count = c;
      else if (c != count)
        throw std::invalid_argument("sources " + std::to_string(mSourceIds[0]) + " and " +
                                    std::to_string(id) + " hold " + std::to_string(count) +
                                    " and " + std::to_string(c) + " particles on frame " +
                                    std::to_string(t) + "; h needs equal counts N(t)");
    }
    if (n == 0 || count == 0) continue;  // nothing emitted yet: the term is undefined, not zero
    mCounts.push_back(count);
    mCoordinates += 3 * std::size_t(count);
    for (std::size_t a = 0; a < n; ++a)
      mLines.push_back(&f.positions[offsets[std::size_t(mSourceIds[a])]].x);
  }
}

double squaredDifference(const float* a, const float* b, std::size_t count) {
  // Eight independent lanes (four SSE2 registers of two doubles once vectorized), so that the
  // additions do not wait on each other; element k always goes to lane k mod 8.
  double s[8] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  std::size_t k = 0;
  for (; k + 8 <= count; k += 8)
    for (std::size_t j = 0; j < 8; ++j) {
      const double d = double(a[k + j]) - double(b[k + j]);
      s[j] += d * d;
    }
  for (std::size_t j = 0; k + j < count; ++j) {
    const double d = double(a[k + j]) - double(b[k + j]);
    s[j] += d * d;
  }
  return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

double streakDistanceBelow(const StreakGroup& g, int a, int b, double limit) {
  double total = 0.0;
  for (int f = 0; f < g.usedFrameCount(); ++f) {
    const int N = g.particleCount(f);
    total += squaredDifference(g.line(f, a), g.line(f, b), 3 * std::size_t(N)) / double(N);
    if (total >= limit) return total;
  }
  return total;
}

double streakDistance(const StreakGroup& g, int a, int b) {
  return streakDistanceBelow(g, a, b, std::numeric_limits<double>::infinity());
}

}  // namespace plume
