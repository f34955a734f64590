/// \file flowgraph_prepared_test.cpp
/// Prepared groups and their cache in the synthesis ([Graph Fire Synthesis] §5.2, eq. 13):
/// emitting a node from the cache of prepared groups, or sharing one prepared group between two
/// live slots, gives bit for bit the particles of emitting a fresh copy of the group read from
/// its file, at any thread count; the cache keeps its byte budget, least recently used out.

#include "flowgraph/prepared_group.h"
#include "flowgraph/prepared_group_cache.h"
#include "flowgraph/synthesizer.h"
#include "flowgraph/pathline_file.h"
#include "tests/flowgraph_groups.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>
#include "tests/temp_path.h"

namespace plume {
namespace {

/// u_ext = (0.3 + 0.5 z, -0.2 x, 0.1): a field whose Heun integral depends on each particle.
struct SkewField final : ExternalVelocity {
  void evaluate(const glm::vec3* x, int n, double t, glm::vec3* out) const override {
    for (int m = 0; m < n; ++m) out[m] = glm::vec3(0.3f + 0.5f * x[m].z, -0.2f * x[m].x, 0.1f + 0.01f * float(t));
  }
};

/// A pathline file of one state's oscillating groups (|Ω| = 700: two parallel chunks, L = 6).
class PreparedGroups : public ::testing::Test {
 protected:
  static constexpr int kNodes = 10;
  void SetUp() override {
    mPath = plume::test::tempPath(std::string("prepared_") +
                                  ::testing::UnitTest::GetInstance()->current_test_info()->name() +
                                  ".bin");
    const std::vector<PathlineGroup> groups = testing::oscillatingGroups({kNodes}, 700, 6, 5);
    PathlineFileInfo info;
    info.layout = groups[0].layout;
    info.resolution = glm::ivec3(8);
    info.cellSize = 0.1f;
    PathlineFileWriter w(mPath, info);
    for (const PathlineGroup& g : groups) w.append(g);
    w.finish();
  }
  void TearDown() override { std::remove(mPath.c_str()); }

  /// One step of the walk: uniform wind varying with n, a field every third step.
  template <typename Emit>
  static void stepWith(int n, const Emit& emit) {
    static const SkewField field;
    if (n % 3 == 2) emit(field);
    else emit(glm::vec3(0.1f * float(n % 4), 0.f, -0.05f));
  }

  /// The particles after each step of `walk`: nodes emitted with stepNode() through a cache of
  /// `cacheBytes` (copies == false), or as fresh copies read with readGroup() and emitted with
  /// step() (copies == true).
  std::vector<SynthParticles> run(const std::vector<int>& walk, int threads, std::size_t cacheBytes,
                                  bool copies, long long* misses = nullptr) const {
    const PathlineFile file = PathlineFile::open(mPath);
    Synthesizer s(file.layout(), threads, cacheBytes);
    std::vector<SynthParticles> out(walk.size());
    for (std::size_t n = 0; n < walk.size(); ++n) {
      const int node = walk[n];
      stepWith(int(n), [&](const auto& u) {
        if (copies) s.step(file.readGroup(node), u);
        else s.stepNode(file, node, 0, u);
      });
      EXPECT_LE(s.cache().bytes(), cacheBytes);
      s.gather(out[n]);
    }
    if (misses) *misses = s.cache().misses();
    return out;
  }

  std::string mPath;
};

void expectSameParticles(const std::vector<SynthParticles>& a, const std::vector<SynthParticles>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t n = 0; n < a.size(); ++n) {
    ASSERT_EQ(a[n].positions, b[n].positions) << "after step " << n;
    ASSERT_EQ(a[n].density, b[n].density) << "after step " << n;
    ASSERT_EQ(a[n].temperature, b[n].temperature) << "after step " << n;
  }
}

TEST_F(PreparedGroups, CacheOnOrOffGivesTheSameParticlesAtAnyThreadCount) {
  // Temporal runs with jumps back (transitions) to nodes visited long before and just before:
  // every emission beyond the first visits is a cache hit when the budget holds all nodes.
  const std::vector<int> walk = {0, 1, 2, 3, 4, 5, 6, 7, 2, 3, 4, 5, 6, 7, 8, 9, 1, 2, 3, 4, 5, 3, 4, 5, 3, 4};
  const std::size_t group = preparedGroupBytes({700, 6, 1.f / 48.f});
  const std::vector<SynthParticles> reference = run(walk, 1, 0, true);
  long long misses = 0;
  for (int threads : {1, 2}) {
    expectSameParticles(run(walk, threads, 0, false, &misses), reference);
    EXPECT_EQ(misses, (long long)walk.size());  // no budget: every visit reads its file
    expectSameParticles(run(walk, threads, kNodes * group, false, &misses), reference);
    EXPECT_EQ(misses, kNodes);  // all fit: each node read once
    // Room for 3 groups: evicted groups still emitted by live slots stay valid.
    expectSameParticles(run(walk, threads, 3 * group + group / 2, false, &misses), reference);
    EXPECT_GT(misses, kNodes);
    EXPECT_LT(misses, (long long)walk.size());
  }
}

TEST_F(PreparedGroups, OneGroupSharedByTwoLiveSlotsEqualsTwoCopies) {
  // L = 6: node 3 is emitted at steps 1, 3 and 4 and node 5 at steps 2 and 5, so with the cache
  // two or three live slots reference one prepared group at once, each with its own u_ext part
  // (uniform winds and a field that depends on the particle's own position).
  const std::vector<int> walk = {3, 3, 5, 3, 3, 5, 6, 7, 3, 4};
  const std::size_t group = preparedGroupBytes({700, 6, 1.f / 48.f});
  long long misses = 0;
  const std::vector<SynthParticles> shared = run(walk, 2, kNodes * group, false, &misses);
  EXPECT_EQ(misses, 5);  // nodes 3, 5, 6, 7, 4
  expectSameParticles(shared, run(walk, 2, 0, true));
  expectSameParticles(shared, run(walk, 1, 0, true));
}

TEST_F(PreparedGroups, StepNodeFailsBeforeChangingAnything) {
  const PathlineFile file = PathlineFile::open(mPath);
  Synthesizer s(file.layout(), 1, 1 << 20);
  s.stepNode(file, 0, 0);
  EXPECT_THROW(s.stepNode(file, kNodes, 0), std::out_of_range);
  EXPECT_EQ(s.steps(), 1);
  Synthesizer other({700, 7, 1.f / 48.f});
  EXPECT_THROW(other.stepNode(file, 0, 0), std::invalid_argument);
  EXPECT_EQ(other.steps(), 0);
}

std::shared_ptr<const PreparedGroup> prepared(int state, int step, int particles) {
  auto g = std::make_shared<PreparedGroup>();
  PathlineGroup source = testing::oscillatingGroups({1}, particles, 4, 3)[0];
  source.state = state;
  source.step = step;
  prepareGroup(source, *g);
  return g;
}

TEST(PreparedGroupCache, EvictsLeastRecentlyUsedWithinItsBudget) {
  const std::size_t bytes = prepared(0, 0, 50)->bytes();
  EXPECT_EQ(bytes, preparedGroupBytes({50, 4, 1.f / 48.f}));
  PreparedGroupCache cache(2 * bytes + bytes / 2);  // room for two
  cache.insert(prepared(0, 0, 50));
  cache.insert(prepared(1, 0, 50));
  EXPECT_NE(cache.find(0, 0), nullptr);  // (0, 0) becomes the most recent
  cache.insert(prepared(0, 7, 50));      // evicts (1, 0), the least recent
  EXPECT_EQ(cache.size(), 2u);
  EXPECT_EQ(cache.bytes(), 2 * bytes);
  EXPECT_EQ(cache.find(1, 0), nullptr);
  EXPECT_NE(cache.find(0, 7), nullptr);
  EXPECT_NE(cache.find(0, 0), nullptr);
  EXPECT_EQ(cache.hits(), 3);
  EXPECT_EQ(cache.misses(), 1);
  cache.insert(prepared(0, 0, 50));  // the same key again replaces it
  EXPECT_EQ(cache.size(), 2u);
  EXPECT_EQ(cache.bytes(), 2 * bytes);
  cache.insert(prepared(2, 0, 200));  // larger than the whole budget: not held
  EXPECT_EQ(cache.find(2, 0), nullptr);
  EXPECT_EQ(cache.size(), 2u);
  // An evicted group stays alive for whoever still holds it.
  const std::shared_ptr<const PreparedGroup> held = cache.find(0, 7);
  cache.clear();
  EXPECT_EQ(cache.bytes(), 0u);
  EXPECT_EQ(held->path.size(), 50u * 4u);
  PreparedGroupCache none(0);
  none.insert(prepared(0, 0, 50));
  EXPECT_EQ(none.size(), 0u);
}

TEST(PreparedGroupCache, PreparedPathIsTheTrapezoidSumOfEachPathline) {
  PathlineGroup g = testing::oscillatingGroups({1}, 9, 5, 4)[0];
  PreparedGroup p;
  prepareGroup(g, p);
  const float h = g.layout.sampleDt;
  for (int q = 0; q < 9; ++q) {
    glm::vec3 x = g.start[std::size_t(q)];
    for (int a = 0; a < 5; ++a) {
      const std::size_t at = std::size_t(a * 9 + q);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(p.path[at][c], x[c], 1e-6f);
      EXPECT_EQ(p.density[at], g.density[g.index(q, a)]);
      EXPECT_EQ(p.temperature[at], g.temperature[g.index(q, a)]);
      if (a + 1 < 5) x += 0.5f * h * (g.velocity[g.index(q, a)] + g.velocity[g.index(q, a + 1)]);
    }
  }
}

}  // namespace
}  // namespace plume
