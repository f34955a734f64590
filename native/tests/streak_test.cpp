/// \file streak_test.cpp
/// Streak surfaces §3.3 ([Smoke Surfaces]): h and the default h0 against the paper's formula on
/// random data, the brute-force reference (clusters by transitive closure, threshold rules,
/// Figure 5), the greedy order on shuffled parallel streaklines, whole surfaces per candidate
/// group, the streak file format, and the time of 20 sources × 300 frames.

#include "core/parallel.h"
#include "core/rng.h"
#include "tracers/streak_file.h"
#include "streak/brute_force.h"
#include "streak/clustering.h"
#include "streak/streak_moments.h"
#include "streak_shots.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <numeric>
#include <set>
#include <stdexcept>
#include "tests/temp_path.h"

namespace fs = std::filesystem;

namespace plume {
namespace {

/// The paper's formula, literally: h(α,β) = Σ_t [Σ_{i=1}^{N(t)} |p(α,t,i) − p(β,t,i)|²] / N(t).
double bruteH(const std::vector<StreakFrame>& frames, int alpha, int beta) {
  double h = 0.0;
  for (const StreakFrame& f : frames) {
    const int N = f.counts[std::size_t(alpha)];
    if (N == 0) continue;
    std::size_t oa = 0, ob = 0;
    for (int s = 0; s < alpha; ++s) oa += std::size_t(f.counts[std::size_t(s)]);
    for (int s = 0; s < beta; ++s) ob += std::size_t(f.counts[std::size_t(s)]);
    double sum = 0.0;
    for (int i = 0; i < N; ++i) {
      const glm::dvec3 d = glm::dvec3(f.positions[oa + std::size_t(i)]) - glm::dvec3(f.positions[ob + std::size_t(i)]);
      sum += glm::dot(d, d);
    }
    h += sum / N;
  }
  return h;
}

/// Clusters by transitive closure of the relation h < h0 (Warshall), singletons dropped.
std::vector<std::vector<int>> bruteClusters(const DistanceMatrix& h, double h0) {
  const int n = h.size;
  std::vector<std::vector<char>> r(std::size_t(n), std::vector<char>(std::size_t(n), 0));
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) r[std::size_t(a)][std::size_t(b)] = a == b || h(a, b) < h0;
  for (int k = 0; k < n; ++k)
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        if (r[std::size_t(a)][std::size_t(k)] && r[std::size_t(k)][std::size_t(b)]) r[std::size_t(a)][std::size_t(b)] = 1;
  std::set<std::vector<int>> sets;
  for (int a = 0; a < n; ++a) {
    std::vector<int> c;
    for (int b = 0; b < n; ++b)
      if (r[std::size_t(a)][std::size_t(b)]) c.push_back(b);
    if (c.size() >= 2) sets.insert(c);
  }
  std::vector<std::vector<int>> out(sets.begin(), sets.end());
  std::sort(out.begin(), out.end(), [](const auto& x, const auto& y) { return x[0] < y[0]; });
  return out;
}

TEST(StreakDistance, MatchesTheFormulaOnRandomData) {
  struct Case {
    int sources;
    std::vector<int> n;
  };
  const std::vector<Case> cases{{2, {1}},
                                {3, {0, 1, 2, 3}},
                                {5, {4, 0, 7, 2, 9, 9, 1}},
                                {13, {1, 2, 3, 5, 8, 13, 21, 34, 0, 17}},
                                {8, std::vector<int>(30, 6)}};
  std::uint64_t seed = 1;
  for (const Case& c : cases) {
    const auto frames = randomFrames(c.sources, c.n, seed++);
    // The sources in reverse as the group's members.
    std::vector<int> ids = iota(c.sources);
    std::reverse(ids.begin(), ids.end());
    const StreakGroup group(share(frames), ids);
    const DistanceMatrix h = bruteForceDistances(group);
    ASSERT_EQ(h.size, c.sources);
    double mean = 0.0;
    for (int a = 0; a < h.size; ++a) {
      EXPECT_EQ(h.values[std::size_t(a * h.size + a)], 0.0);
      for (int b = a + 1; b < h.size; ++b) {
        const double expected = bruteH(frames, ids[std::size_t(a)], ids[std::size_t(b)]);
        EXPECT_NEAR(h(a, b), expected, 1e-12 * std::max(1.0, expected));
        EXPECT_EQ(h.values[std::size_t(a * h.size + b)], h.values[std::size_t(b * h.size + a)]);
        EXPECT_EQ(h(a, b), streakDistance(group, b, a));  // symmetric, bit for bit
        mean += expected;
      }
    }
    mean /= 0.5 * h.size * (h.size - 1);
    // The default h0 from centred sums equals the mean over the pairs.
    EXPECT_NEAR(streakMoments(group).meanDistance, mean, 1e-12 * mean);
    EXPECT_NEAR(bruteForceMean(h), mean, 1e-12 * mean);
    // The reference clusters equal the transitive closure, the default h0 included; the
    // sparse clusters equal both (distances held up to the largest threshold).
    std::vector<double> values;
    for (int a = 0; a < h.size; ++a)
      for (int b = a + 1; b < h.size; ++b) values.push_back(h(a, b));
    std::sort(values.begin(), values.end());
    std::vector<double> thresholds{0.0, bruteForceMean(h), values.back() * 2.0};
    for (double q : {0.1, 0.3, 0.5, 0.7, 0.9}) thresholds.push_back(values[std::size_t(q * double(values.size() - 1))]);
    DistanceParams params;
    params.reach = values.back() * 2.0;
    const StreakDistances sparse(group, params);
    for (double h0 : thresholds) {
      const auto clusters = bruteForceClusters(h, h0);
      EXPECT_EQ(clusters, bruteClusters(h, h0)) << "h0 " << h0;
      EXPECT_EQ(clusterSources(sparse, h0), clusters) << "h0 " << h0;
      const ClusterSummary s = bruteForceSummary(h, h0);
      EXPECT_EQ(s.surfaces, int(clusters.size()));
      int used = 0;
      for (const auto& cl : clusters) used += int(cl.size());
      EXPECT_EQ(s.streaklines, used);
      EXPECT_EQ(clusterSummary(sparse, h0).surfaces, s.surfaces);
      EXPECT_EQ(clusterSummary(sparse, h0).streaklines, s.streaklines);
    }
  }
}

TEST(StreakDistance, SkipsEmptyFramesAndRejectsUnequalCounts) {
  auto frames = randomFrames(3, {0, 2, 0, 3}, 9);
  const StreakGroup group(share(frames), {0, 1, 2});
  EXPECT_EQ(group.usedFrameCount(), 2);
  EXPECT_EQ(group.coordinateCount(), 15u);
  EXPECT_NEAR(streakDistance(group, 0, 2), bruteH(frames, 0, 2), 1e-12);
  frames[1].counts = {2, 1, 3};
  try {
    StreakGroup(share(frames), {0, 1, 2});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("equal counts"), std::string::npos) << e.what();
  }
  EXPECT_THROW(StreakGroup(share(randomFrames(3, {2}, 1)), {0, 3}), std::invalid_argument);
  auto short_ = randomFrames(3, {2}, 1);
  short_[0].positions.pop_back();
  EXPECT_THROW(StreakGroup(share(short_), {0, 1}), std::invalid_argument);
}

TEST(StreakDistance, StopsEarlyOnlyAboveTheLimit) {
  const auto frames = randomFrames(4, {3, 5, 8, 13}, 21);
  const StreakGroup group(share(frames), iota(4));
  const double h = streakDistance(group, 1, 3);
  EXPECT_EQ(streakDistanceBelow(group, 1, 3, std::nextafter(h, 1e300)), h);  // below the limit: h itself
  const double partial = streakDistanceBelow(group, 1, 3, 0.25 * h);
  EXPECT_GE(partial, 0.25 * h);
  EXPECT_LE(partial, h);
  EXPECT_LT(partial, h);  // stopped before the last frame
}

TEST(StreakDistance, SameResultWithOneAndTwoThreads) {
  const StreakGroup group(share(randomFrames(17, {3, 5, 8, 13, 21, 34}, 5)), iota(17));
  DistanceMatrix h1, h2;
  double m1 = 0, m2 = 0;
  {
    ThreadLimit limit(1);
    h1 = bruteForceDistances(group);
    m1 = streakMoments(group).meanDistance;
  }
  {
    ThreadLimit limit(2);
    h2 = bruteForceDistances(group);
    m2 = streakMoments(group).meanDistance;
  }
  EXPECT_EQ(std::memcmp(h1.values.data(), h2.values.data(), h1.values.size() * sizeof(double)), 0);
  EXPECT_EQ(m1, m2);
}

TEST(Clustering, ThresholdRulesAndSingletons) {
  DistanceMatrix h;
  h.size = 4;
  // 0-1 close, 2-3 close, cross pairs far.
  h.values = {0, 1, 9, 9, 1, 0, 9, 9, 9, 9, 0, 2, 9, 9, 2, 0};
  EXPECT_EQ(bruteForceClusters(h, 1.5), (std::vector<std::vector<int>>{{0, 1}}));  // 2-3 has h = 2
  EXPECT_EQ(bruteForceClusters(h, 2.5), (std::vector<std::vector<int>>{{0, 1}, {2, 3}}));
  EXPECT_EQ(bruteForceClusters(h, 1.0).size(), 0u);  // strict: h < h0
  const ClusterSummary s = bruteForceSummary(h, 100.0);
  EXPECT_EQ(s.surfaces, 1);
  EXPECT_EQ(s.streaklines, 4);
  EXPECT_THROW(bruteForceClusters(h, -1.0), std::invalid_argument);
  EXPECT_THROW(bruteForceSummary(h, NAN), std::invalid_argument);
  DistanceMatrix one;
  one.size = 1;
  one.values = {0};
  EXPECT_THROW(bruteForceMean(one), std::invalid_argument);

  // The same rules on sparse distances: one-particle streaklines with h(0,1) = 1, h(2,3) = 2,
  // h(1,2) = 81, h(0,2) = 100, h(1,3) = 101, h(0,3) = 122 (exact in float).
  StreakFrame f;
  f.counts = {1, 1, 1, 1};
  f.groups = {0, 0, 0, 0};
  f.positions = {{0, 0, 0}, {1, 0, 0}, {10, 0, 0}, {11, 1, 0}};
  const StreakGroup group(share({f}), iota(4));
  DistanceParams params;
  params.reach = 100.0;
  const StreakDistances sparse(group, params);
  EXPECT_EQ(sparse.pairCount(), 3u);  // h(0,2) = 100 is not below the reach 100
  EXPECT_EQ(clusterSummary(sparse, 100.0).streaklines, 4);  // joined through h(1,2) = 81
  EXPECT_EQ(clusterSources(sparse, 1.5), (std::vector<std::vector<int>>{{0, 1}}));
  EXPECT_EQ(clusterSources(sparse, 2.5), (std::vector<std::vector<int>>{{0, 1}, {2, 3}}));
  EXPECT_EQ(clusterSources(sparse, 1.0).size(), 0u);
  EXPECT_EQ(clusterSummary(sparse, 2.0).surfaces, 1);
  EXPECT_EQ(clusterSummary(sparse, 2.5).surfaces, 2);
  EXPECT_THROW(clusterSources(sparse, -1.0), std::invalid_argument);
  EXPECT_THROW(clusterSummary(sparse, NAN), std::invalid_argument);
  EXPECT_THROW(clusterSources(sparse, 100.5), std::invalid_argument);  // above the reach
  EXPECT_THROW(StreakDistances(StreakGroup(share({f}), {2})), std::invalid_argument);  // default h0 of 1
}

TEST(Ordering, RecoversShuffledParallelStreaklines) {
  for (int n : {2, 3, 5, 9, 16}) {
    for (std::uint64_t seed = 0; seed < 5; ++seed) {
      // slotOfSource: a random permutation of 0..n-1 (Fisher–Yates with a seeded Rng).
      std::vector<int> slot = iota(n);
      Rng rng(seed, std::uint64_t(n));
      for (int i = n - 1; i > 0; --i) std::swap(slot[std::size_t(i)], slot[std::size_t(rng.next() % std::uint64_t(i + 1))]);
      const StreakGroup group(share(parallelStreaks(slot, 0.05f, 12)), iota(n));
      const StreakDistances h(group);  // reach: the mean; the order needs h beyond it too
      const std::vector<int> order = orderGreedy(h, iota(n));
      EXPECT_EQ(order, bruteForceOrder(bruteForceDistances(group), iota(n)));
      std::vector<int> slots;
      for (int m : order) slots.push_back(slot[std::size_t(m)]);
      std::vector<int> up = iota(n), down(up.rbegin(), up.rend());
      EXPECT_TRUE(slots == up || slots == down) << "n " << n << " seed " << seed;
    }
  }
}

TEST(Ordering, FigureFiveAndMembersSubset) {
  // h(a,c) < h(a,b) < h(b,c): the minimum-length order is b - a - c (or reversed).
  DistanceMatrix h;
  h.size = 3;
  h.values = {0, 2, 1, 2, 0, 3, 1, 3, 0};
  const auto order = bruteForceOrder(h, {0, 1, 2});
  EXPECT_TRUE(order == (std::vector<int>{2, 0, 1}) || order == (std::vector<int>{1, 0, 2}));
  EXPECT_EQ(bruteForceOrder(h, {2}), std::vector<int>{2});
  EXPECT_EQ(bruteForceOrder(h, {1, 2}), (std::vector<int>{1, 2}));
  EXPECT_THROW(bruteForceOrder(h, {0, 0}), std::invalid_argument);
  EXPECT_THROW(bruteForceOrder(h, {3}), std::invalid_argument);
  // Figure 5 on streaklines: a at 0, c at 1, b at -1.5 (h(a,c) = 1 < h(a,b) = 2.25 < h(b,c)).
  StreakFrame f;
  f.counts = {1, 1, 1};
  f.groups = {0, 0, 0};
  f.positions = {{0, 0, 0}, {-1.5f, 0, 0}, {1, 0, 0}};
  const StreakDistances sparse(StreakGroup(share({f}), iota(3)));
  EXPECT_EQ(sparse.pairCount(), 2u);  // below the mean (1 + 2.25 + 6.25) / 3: a-c and a-b
  const auto sparseOrder = orderGreedy(sparse, {0, 1, 2});
  EXPECT_TRUE(sparseOrder == (std::vector<int>{2, 0, 1}) || sparseOrder == (std::vector<int>{1, 0, 2}));
  EXPECT_EQ(orderGreedy(sparse, {2}), std::vector<int>{2});
  EXPECT_EQ(orderGreedy(sparse, {1, 2}), (std::vector<int>{1, 2}));  // the one pair beyond the reach
  EXPECT_THROW(orderGreedy(sparse, {0, 0}), std::invalid_argument);
  EXPECT_THROW(orderGreedy(sparse, {3}), std::invalid_argument);
}

TEST(BuildSurfaces, OneOrderedSurfacePerSeparatedGroupOfLines) {
  // Two bundles far apart, so the default h0 (mean) separates them: bundle A slots 0..2,
  // bundle B slots 40..42.
  const std::vector<int> slot{41, 0, 40, 2, 42, 1};
  auto frames = parallelStreaks(slot, 0.05f, 6);
  const std::vector<int> groups(6, 7);
  const auto surfaces = buildSurfaces(frames, groups, -1.0);
  ASSERT_EQ(surfaces.size(), 2u);
  EXPECT_EQ(surfaces[0].group, 7);
  auto slotsOf = [&](const StreakSurface& s) {
    std::vector<int> v;
    for (int id : s.sources) v.push_back(slot[std::size_t(id)]);
    if (v.front() > v.back()) std::reverse(v.begin(), v.end());
    return v;
  };
  EXPECT_EQ(slotsOf(surfaces[0]), (std::vector<int>{40, 41, 42}));  // first member: source 0
  EXPECT_EQ(slotsOf(surfaces[1]), (std::vector<int>{0, 1, 2}));
  const auto reference = bruteForceSurfaces(frames, groups, -1.0);
  ASSERT_EQ(reference.size(), surfaces.size());
  for (std::size_t s = 0; s < surfaces.size(); ++s) {
    EXPECT_EQ(reference[s].sources, surfaces[s].sources);
    EXPECT_EQ(reference[s].threshold, surfaces[s].threshold);
  }
  // A huge explicit h0 joins everything into one surface.
  EXPECT_EQ(buildSurfaces(frames, groups, 1e9)[0].sources.size(), 6u);
  // A group with one source is an error naming it.
  try {
    buildSurfaces(frames, {7, 7, 7, 7, 7, 3}, -1.0);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("candidate group 3"), std::string::npos);
  }
}

TEST(BuildSurfaces, TwentySourcesThreeHundredFramesTiming) {
  // The benchmark size: 20 point sources, 300 frames, two substeps a frame (N(t) = 2t + 1).
  const int sources = 20, frames = 300;
  std::vector<int> n;
  for (int t = 1; t <= frames; ++t) n.push_back(2 * t + 1);
  const auto data = randomFrames(sources, n, 3);
  const std::vector<int> groups(std::size_t(sources), 0);
  const auto t0 = std::chrono::steady_clock::now();
  const StreakDistances h(StreakGroup(share(data), iota(sources)));
  const auto t1 = std::chrono::steady_clock::now();
  const auto surfaces = buildSurfaces(data, groups, -1.0);
  const auto t2 = std::chrono::steady_clock::now();
  const ClusterSummary s = clusterSummary(h, defaultThreshold(h));
  const auto t3 = std::chrono::steady_clock::now();
  const auto reference = bruteForceSurfaces(data, groups, -1.0);
  const auto t4 = std::chrono::steady_clock::now();
  using ms = std::chrono::duration<double, std::milli>;
  std::printf("[ timing ] 20 sources x 300 frames (%zu particles/frame at the end): distances "
              "%.1f ms (%zu pairs held), buildSurfaces %.1f ms (%zu surfaces), clusterSummary "
              "%.3f ms, brute force %.1f ms\n",
              data.back().positions.size(), ms(t1 - t0).count(), h.pairCount(), ms(t2 - t1).count(),
              surfaces.size(), ms(t3 - t2).count(), ms(t4 - t3).count());
  EXPECT_GT(s.streaklines, 0);
  ASSERT_EQ(reference.size(), surfaces.size());
  for (std::size_t k = 0; k < surfaces.size(); ++k) EXPECT_EQ(reference[k].sources, surfaces[k].sources);
}

// --- streak files -------------------------------------------------------------------------------

fs::path scratchDir(const std::string& name) {
  const fs::path dir = fs::path(plume::test::tempPath("streak_test_" + name));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<char> readBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void writeBytes(const fs::path& p, const std::vector<char>& b) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(b.data(), std::streamsize(b.size()));
}

std::string readError(const fs::path& p) {
  try {
    readStreakFile(p.string());
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "no exception";
}

TEST(StreakFile, RoundTripIsExact) {
  const fs::path dir = scratchDir("roundtrip");
  EXPECT_EQ(streakFileName(7), "streaks_0007.bin");
  StreakFrame f = randomFrames(5, {4}, 11)[0];
  f.counts = {0, 3, 9, 4, 4};  // unequal counts are fine in the file
  f.groups = {0, 0, 2, -1, 5};
  const fs::path path = dir / streakFileName(12);
  writeStreakFile(path.string(), f);
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
  const StreakFrame g = readStreakFile(path.string());
  EXPECT_EQ(g.counts, f.counts);
  EXPECT_EQ(g.groups, f.groups);
  EXPECT_EQ(g.outside, f.outside);
  EXPECT_EQ(g.density, f.density);
  ASSERT_EQ(g.positions.size(), f.positions.size());
  EXPECT_EQ(std::memcmp(g.positions.data(), f.positions.data(), f.positions.size() * 12), 0);
  // An empty frame too.
  writeStreakFile(path.string(), StreakFrame{});
  EXPECT_EQ(readStreakFile(path.string()).sourceCount(), 0);
  // Inconsistent frames are refused before writing.
  f.density.pop_back();
  EXPECT_THROW(writeStreakFile(path.string(), f), std::invalid_argument);
}

TEST(StreakFile, CorruptAndTruncatedFilesAreRejected) {
  const fs::path dir = scratchDir("corrupt");
  const fs::path good = dir / "streaks_0001.bin", bad = dir / "streaks_0002.bin";
  writeStreakFile(good.string(), randomFrames(4, {6}, 2)[0]);
  const std::vector<char> bytes = readBytes(good);

  EXPECT_NE(readError(dir / "missing.bin").find("cannot be opened"), std::string::npos);
  // Every truncation is rejected, naming the file.
  for (std::size_t size : {std::size_t(0), std::size_t(5), std::size_t(20), bytes.size() / 2, bytes.size() - 1}) {
    writeBytes(bad, std::vector<char>(bytes.begin(), bytes.begin() + std::ptrdiff_t(size)));
    const std::string e = readError(bad);
    EXPECT_NE(e.find(bad.string()), std::string::npos) << e;
    EXPECT_EQ(e.find("no exception"), std::string::npos);
  }
  // A flipped byte anywhere in the payload fails the checksum (or a size check).
  for (std::size_t at : {std::size_t(30), bytes.size() / 2, bytes.size() - 9}) {
    std::vector<char> b = bytes;
    b[at] = char(b[at] ^ 0x40);
    writeBytes(bad, b);
    EXPECT_NE(readError(bad).find("corrupt"), std::string::npos) << at;
  }
  // Bad magic, newer version.
  std::vector<char> b = bytes;
  b[0] = 'X';
  writeBytes(bad, b);
  EXPECT_NE(readError(bad).find("bad magic"), std::string::npos);
  b = bytes;
  b[9] = 2;
  writeBytes(bad, b);
  EXPECT_NE(readError(bad).find("version 2"), std::string::npos);
  // A forged header announcing 2^32 - 1 sources or a huge count is refused before allocating.
  b = bytes;
  for (int i = 13; i < 17; ++i) b[std::size_t(i)] = char(0xff);
  writeBytes(bad, b);
  EXPECT_NE(readError(bad).find("do not fit"), std::string::npos);
  b = bytes;
  for (int i = 17; i < 21; ++i) b[std::size_t(i)] = i == 20 ? char(0x7f) : char(0xff);
  writeBytes(bad, b);
  EXPECT_NE(readError(bad).find("do not fit"), std::string::npos);
  // Trailing bytes change the size.
  b = bytes;
  b.push_back(0);
  writeBytes(bad, b);
  EXPECT_NE(readError(bad).find("truncated or corrupt"), std::string::npos);
}

TEST(StreakFile, NonFiniteValuesAreRefusedByName) {
  // A checksum-valid file (its own writer's) holding NaN or infinity: those would become grid
  // cell indices when the streaklines are paired (streak/candidate_pairs.cpp).
  const fs::path dir = scratchDir("nonfinite");
  const fs::path bad = dir / "streaks_0003.bin";
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  for (int which = 0; which < 3; ++which) {
    StreakFrame f = randomFrames(4, {6}, 2)[0];
    if (which == 0) f.positions[5].y = nan;
    if (which == 1) f.positions[2].z = -inf;
    if (which == 2) f.density[3] = inf;
    writeStreakFile(bad.string(), f);
    const std::string e = readError(bad);
    EXPECT_NE(e.find(bad.string()), std::string::npos) << e;
    EXPECT_NE(e.find("non-finite"), std::string::npos) << e;
  }
}

TEST(StreakFile, UnwritablePathThrowsNamingIt) {
  const std::string path = "/nonexistent_plume_dir/streaks_0001.bin";
  try {
    writeStreakFile(path, StreakFrame{});
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
  }
}

}  // namespace
}  // namespace plume
