/// \file streak_cluster_test.cpp
/// The sparse clustering of §3.3 ([Smoke Surfaces]) against the brute force over all pairs, on
/// random shots (clustered, uniform and coincident layouts, frames with N(t) = 0, several seeds):
/// the same pairs below the reach with bit-identical h, the same default h0 to 1e-12, the same
/// clusters, counts and greedy orders, at any thread count.

#include "core/parallel.h"
#include "core/rng.h"
#include "streak/brute_force.h"
#include "streak/clustering.h"
#include "streak/streak_moments.h"
#include "streak_shots.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace plume {
namespace {

struct Shot {
  std::string name;
  std::vector<StreakFrame> frames;
};

/// Shots of 60–90 sources with empty frames among the used ones.
std::vector<Shot> shots() {
  const std::vector<int> counts{0, 2, 3, 0, 5, 8, 0, 13, 9};
  std::vector<Shot> out;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const std::string s = " seed " + std::to_string(seed);
    out.push_back({"clustered" + s, plumeFrames(90, counts, Layout::Clustered, 12, seed)});
    out.push_back({"uniform" + s, plumeFrames(60, counts, Layout::Uniform, 1, seed)});
    out.push_back({"coincident" + s, plumeFrames(75, counts, Layout::Coincident, 9, seed)});
  }
  return out;
}

/// Distances held up to `reach` (< 0: the default h0) with the pruning directions in use even
/// for these small groups (minSize 0), so that the grid and the bound are what is tested.
StreakDistances pruned(const StreakGroup& g, double reach = -1.0, int rank = 16) {
  DistanceParams params;
  params.reach = reach;
  params.projection.rank = rank;
  params.projection.sampleSize = 32;
  params.projection.minSize = 0;
  return StreakDistances(g, params);
}

/// The values of h over the pairs, ascending.
std::vector<double> upperValues(const DistanceMatrix& h) {
  std::vector<double> v;
  for (int a = 0; a < h.size; ++a)
    for (int b = a + 1; b < h.size; ++b) v.push_back(h(a, b));
  std::sort(v.begin(), v.end());
  return v;
}

/// Members in a seeded random order.
std::vector<int> shuffled(int n, std::uint64_t seed) {
  std::vector<int> v = iota(n);
  Rng rng(seed, 7);
  for (int i = n - 1; i > 0; --i)
    std::swap(v[std::size_t(i)], v[std::size_t(rng.next() % std::uint64_t(i + 1))]);
  return v;
}

/// Everything the sparse distances claim, checked against the matrix for h0 in `thresholds`.
void expectSameAsBruteForce(const StreakDistances& sparse, const DistanceMatrix& h,
                            const std::vector<double>& thresholds, const std::string& what) {
  // The held pairs are exactly those with h < reach, with the matrix's h bit for bit.
  std::size_t below = 0;
  for (int a = 0; a < h.size; ++a) {
    std::vector<int> expected;
    for (int b = 0; b < h.size; ++b)
      if (b != a && h(a, b) < sparse.reach()) expected.push_back(b);
    below += expected.size();
    const int* held = sparse.neighbours(a);
    ASSERT_EQ(std::vector<int>(held, held + sparse.degree(a)), expected) << what << " member " << a;
    for (int i = 0; i < sparse.degree(a); ++i)
      ASSERT_EQ(sparse.neighbourDistances(a)[i], h(a, sparse.neighbours(a)[i])) << what;
  }
  EXPECT_EQ(sparse.pairCount(), below / 2) << what;
  for (double h0 : thresholds) {
    if (h0 > sparse.reach()) continue;
    const auto clusters = bruteForceClusters(h, h0);
    ASSERT_EQ(clusterSources(sparse, h0), clusters) << what << " h0 " << h0;
    const ClusterSummary s = bruteForceSummary(h, h0), t = clusterSummary(sparse, h0);
    EXPECT_EQ(t.surfaces, s.surfaces) << what << " h0 " << h0;
    EXPECT_EQ(t.streaklines, s.streaklines) << what << " h0 " << h0;
    for (const std::vector<int>& c : clusters)
      ASSERT_EQ(orderGreedy(sparse, c), bruteForceOrder(h, c)) << what << " h0 " << h0;
  }
}

TEST(SparseClustering, EqualsBruteForceOnRandomShots) {
  for (const Shot& shot : shots()) {
    const StreakGroup group(share(shot.frames), iota(shot.frames.back().sourceCount()));
    const DistanceMatrix h = bruteForceDistances(group);
    const std::vector<double> values = upperValues(h);
    const StreakDistances sparse = pruned(group);  // reach: the default h0
    // The default h0 from centred sums is the brute-force mean to 1e-12.
    EXPECT_NEAR(sparse.meanDistance(), bruteForceMean(h), 1e-12 * bruteForceMean(h)) << shot.name;
    EXPECT_EQ(sparse.reach(), sparse.meanDistance());
    // Thresholds across the range, exact values of h among them (h < h0 is strict).
    std::vector<double> thresholds{0.0, 1e-300, sparse.meanDistance()};
    for (double q : {0.005, 0.02, 0.05, 0.1, 0.2, 0.35, 0.5}) {
      const double v = values[std::size_t(q * double(values.size() - 1))];
      thresholds.insert(thresholds.end(), {v, std::nextafter(v, 0.0), std::nextafter(v, 1e300)});
    }
    expectSameAsBruteForce(sparse, h, thresholds, shot.name);
    // The curve of Figure 4 just above and below every value of h up to the reach.
    for (double v : values) {
      if (v >= sparse.reach()) break;
      for (double h0 : {v, std::nextafter(v, 1e300)}) {
        if (h0 > sparse.reach()) continue;
        const ClusterSummary s = bruteForceSummary(h, h0), t = clusterSummary(sparse, h0);
        ASSERT_TRUE(s.surfaces == t.surfaces && s.streaklines == t.streaklines)
            << shot.name << " h0 " << h0;
      }
    }
    // An explicit reach below the default, and orders far beyond it (every member, shuffled):
    // the greedy order then computes h on demand.
    const StreakDistances narrow = sparse.withReach(values[values.size() / 20]);
    expectSameAsBruteForce(narrow, h, thresholds, shot.name + " narrow");
    const std::vector<int> all = shuffled(h.size, values.size());
    EXPECT_EQ(orderGreedy(narrow, all), bruteForceOrder(h, all)) << shot.name;
    EXPECT_EQ(orderGreedy(sparse, all), bruteForceOrder(h, all)) << shot.name;
  }
}

TEST(SparseClustering, ProjectionRankChangesWorkNotResults) {
  const Shot shot = shots()[0];
  const StreakGroup group(share(shot.frames), iota(shot.frames.back().sourceCount()));
  const DistanceMatrix h = bruteForceDistances(group);
  const double reach = upperValues(h)[h.values.size() / 20];
  std::vector<std::uint64_t> exact;
  for (int rank : {0, 1, 3, 16, 40}) {
    const StreakDistances sparse = pruned(group, reach, rank);
    expectSameAsBruteForce(sparse, h, {reach * 0.3, reach * 0.7, reach},
                           "rank " + std::to_string(rank));
    exact.push_back(sparse.stats().exact);
  }
  // The bound earns its keep: with 16 directions far fewer pairs need exact h than with none.
  EXPECT_LT(exact[3], exact[0] / 3) << exact[3] << " vs " << exact[0];
}

TEST(SparseClustering, AllPairsAndNoPairs) {
  const Shot shot = shots()[1];
  const StreakGroup group(share(shot.frames), iota(shot.frames.back().sourceCount()));
  const DistanceMatrix h = bruteForceDistances(group);
  const StreakDistances all = pruned(group, INFINITY);
  EXPECT_EQ(all.pairCount(), std::size_t(h.size) * std::size_t(h.size - 1) / 2);
  expectSameAsBruteForce(all, h, {upperValues(h).back() * 2.0}, "all pairs");
  const StreakDistances none = all.withReach(0.0);
  EXPECT_EQ(none.pairCount(), 0u);
  EXPECT_TRUE(clusterSources(none, 0.0).empty());
  EXPECT_EQ(orderGreedy(none, {4, 1, 3}), bruteForceOrder(h, {4, 1, 3}));
  EXPECT_THROW(all.withReach(-1.0), std::invalid_argument);
  DistanceParams params;
  params.reach = NAN;
  EXPECT_THROW(StreakDistances(group, params), std::invalid_argument);
  params.reach = 1.0;
  params.projection.minSize = -1;
  EXPECT_THROW(StreakDistances(group, params), std::invalid_argument);
}

TEST(SparseClustering, IdenticalStreaklinesGiveZeroDefault) {
  // Every source a copy of source 0: h = 0 for every pair, so the mean is exactly 0 and h < 0
  // joins nothing; an explicit h0 > 0 joins everything, every tie going to the earlier member.
  auto frames = plumeFrames(10, {1, 0, 4, 6}, Layout::Clustered, 1, 5);
  for (StreakFrame& f : frames) {
    const std::vector<std::size_t> o = f.offsets();
    for (int s = 1; s < 10; ++s)
      std::copy(f.positions.begin(), f.positions.begin() + std::ptrdiff_t(o[1]),
                f.positions.begin() + std::ptrdiff_t(o[std::size_t(s)]));
  }
  const StreakGroup group(share(frames), iota(10));
  const StreakDistances zero = pruned(group);
  EXPECT_EQ(zero.meanDistance(), 0.0);
  EXPECT_TRUE(clusterSources(zero, 0.0).empty());
  const StreakDistances some = zero.withReach(1.0);
  const DistanceMatrix h = bruteForceDistances(group);
  expectSameAsBruteForce(some, h, {0.0, 0.5, 1.0}, "identical");
  EXPECT_EQ(orderGreedy(some, iota(10)), bruteForceOrder(h, iota(10)));
}

TEST(SparseClustering, SameResultWithOneAndTwoThreads) {
  const Shot shot = shots()[2];
  const std::vector<int> groups(shot.frames.back().counts.size(), 3);
  auto run = [&](int threads) {
    ThreadLimit limit(threads);
    ProjectionParams projection;
    projection.minSize = 0;
    return std::make_pair(pruned(StreakGroup(share(shot.frames), iota(int(groups.size())))),
                          buildSurfaces(shot.frames, groups, -1.0, projection));
  };
  const auto [d1, s1] = run(1);
  const auto [d2, s2] = run(2);
  EXPECT_EQ(d1.meanDistance(), d2.meanDistance());
  ASSERT_EQ(d1.pairCount(), d2.pairCount());
  for (int a = 0; a < d1.size(); ++a) {
    ASSERT_EQ(d1.degree(a), d2.degree(a));
    const std::size_t k = std::size_t(d1.degree(a));
    EXPECT_EQ(std::memcmp(d1.neighbours(a), d2.neighbours(a), sizeof(int) * k), 0);
    EXPECT_EQ(std::memcmp(d1.neighbourDistances(a), d2.neighbourDistances(a), sizeof(double) * k), 0);
  }
  EXPECT_EQ(d1.curve().values, d2.curve().values);
  EXPECT_EQ(d1.stats().exact, d2.stats().exact);
  ASSERT_EQ(s1.size(), s2.size());
  for (std::size_t k = 0; k < s1.size(); ++k) EXPECT_EQ(s1[k].sources, s2[k].sources);
}

TEST(SparseClustering, BuildSurfacesEqualsBruteForcePerGroup) {
  // Three candidate groups over one shot, default and explicit thresholds.
  const Shot shot = shots()[0];
  std::vector<int> groups;
  for (int s = 0; s < shot.frames.back().sourceCount(); ++s)
    groups.push_back(s % 3 == 0 ? 5 : (s % 3 == 1 ? 2 : 9));
  const StreakGroup g2(share(shot.frames), {1, 4, 7});
  ProjectionParams projection;
  projection.minSize = 0;
  projection.sampleSize = 16;
  for (double h0 : {-1.0, 0.0, 0.5 * streakMoments(g2).meanDistance, 3.0}) {
    const auto sparse = buildSurfaces(shot.frames, groups, h0, projection);
    const auto brute = bruteForceSurfaces(shot.frames, groups, h0);
    ASSERT_EQ(sparse.size(), brute.size()) << "h0 " << h0;
    for (std::size_t k = 0; k < sparse.size(); ++k) {
      EXPECT_EQ(sparse[k].group, brute[k].group);
      EXPECT_EQ(sparse[k].threshold, brute[k].threshold);
      EXPECT_EQ(sparse[k].sources, brute[k].sources) << "h0 " << h0 << " surface " << k;
    }
  }
}

}  // namespace
}  // namespace plume
