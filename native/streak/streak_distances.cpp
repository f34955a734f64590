#include "streak/streak_distances.h"

#include "streak/disjoint_sets.h"
#include "streak/streak_moments.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace plume {
namespace {

/// Kruskal over the pairs sorted by (h, a, b): the counts after each distinct h that joins sets.
ThresholdCurve kruskalCurve(int n, std::vector<DistancePair>& pairs) {
  tbb::parallel_sort(pairs.begin(), pairs.end(), [](const DistancePair& x, const DistancePair& y) {
    if (x.h != y.h) return x.h < y.h;
    return x.a != y.a ? x.a < y.a : x.b < y.b;
  });
  ThresholdCurve curve;
  DisjointSets sets(n);
  ClusterSummary now;
  for (const DistancePair& p : pairs) {
    const int sa = sets.setSize(p.a), sb = sets.setSize(p.b);
    if (!sets.join(p.a, p.b)) continue;
    // A set of >= 2 sources is a surface; singletons take no part.
    now.surfaces += 1 - (sa >= 2) - (sb >= 2);
    now.streaklines += sa + sb - (sa >= 2 ? sa : 0) - (sb >= 2 ? sb : 0);
    if (!curve.values.empty() && curve.values.back() == p.h) {
      curve.counts.back() = now;
    } else {
      curve.values.push_back(p.h);
      curve.counts.push_back(now);
    }
  }
  return curve;
}

}  // namespace

void DistanceParams::validate() const {
  if (std::isnan(reach)) throw std::invalid_argument("reach must be a number (got NaN)");
  projection.validate();
}

ClusterSummary ThresholdCurve::at(double h0) const {
  const auto first = std::lower_bound(values.begin(), values.end(), h0);  // values >= h0
  const auto below = std::size_t(first - values.begin());
  return below == 0 ? ClusterSummary{} : counts[below - 1];
}

StreakDistances::StreakDistances(StreakGroup group, const DistanceParams& params)
    : mGroup(std::move(group)) {
  params.validate();
  if (params.reach < 0.0 && mGroup.size() < 2)
    throw std::invalid_argument(
        "a candidate group needs at least 2 point sources for a default h0 (got " +
        std::to_string(mGroup.size()) + ")");
  const StreakMoments moments = streakMoments(mGroup);
  mMean = moments.meanDistance;
  mProjection = std::make_shared<const StreakProjection>(
      projectStreaks(mGroup, moments.meanLine, params.projection));
  build(params.reach < 0.0 ? mMean : params.reach);
}

StreakDistances::StreakDistances(StreakGroup group,
                                 std::shared_ptr<const StreakProjection> projection, double mean,
                                 double reach)
    : mGroup(std::move(group)), mProjection(std::move(projection)), mMean(mean) {
  build(reach);
}

void StreakDistances::build(double reach) {
  if (std::isnan(reach) || reach < 0.0)
    throw std::invalid_argument("reach must be >= 0 or +inf (got " + std::to_string(reach) + ")");
  mReach = reach;
  CandidatePairs found = findCandidatePairs(mGroup, *mProjection, mReach);
  mStats = found.stats;
  // Symmetric adjacency lists. The pairs come sorted by (a, b), so each list fills ascending:
  // first the neighbours below (as b of earlier rows), then those above (its own row).
  const int n = mGroup.size();
  mOffsets.assign(std::size_t(n) + 1, 0);
  for (const DistancePair& p : found.pairs) {
    ++mOffsets[std::size_t(p.a) + 1];
    ++mOffsets[std::size_t(p.b) + 1];
  }
  for (int a = 0; a < n; ++a) mOffsets[std::size_t(a) + 1] += mOffsets[std::size_t(a)];
  mNeighbours.resize(2 * found.pairs.size());
  mDistances.resize(2 * found.pairs.size());
  std::vector<std::size_t> fill(mOffsets.begin(), mOffsets.end() - 1);
  for (const DistancePair& p : found.pairs) {
    mNeighbours[fill[std::size_t(p.a)]] = p.b;
    mDistances[fill[std::size_t(p.a)]++] = p.h;
    mNeighbours[fill[std::size_t(p.b)]] = p.a;
    mDistances[fill[std::size_t(p.b)]++] = p.h;
  }
  mCurve = kruskalCurve(n, found.pairs);
}

StreakDistances StreakDistances::withReach(double reach) const {
  return StreakDistances(mGroup, mProjection, mMean, reach);
}

double StreakDistances::meanDistance() const {
  if (size() < 2)
    throw std::invalid_argument(
        "a candidate group needs at least 2 point sources for a default h0 (got " +
        std::to_string(size()) + ")");
  return mMean;
}

}  // namespace plume
