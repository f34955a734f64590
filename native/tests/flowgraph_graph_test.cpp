/// \file flowgraph_graph_test.cpp
/// The flow graph of [Graph Fire Synthesis] §4.3-5.1: the cost matrix (eq. 9-10) against a
/// brute-force double implementation and across thread counts, the block candidates and ε
/// (eq. 11), pruning of dead ends, the Figure 4 picture and the errors on bad input (the walks:
/// flowgraph_walk_test.cpp).

#include "flowgraph/cost_matrix.h"
#include "flowgraph/cost_matrix_image.h"
#include "flowgraph/flow_graph.h"
#include "flowgraph/magnitude_weights.h"
#include "flowgraph/random_walk.h"
#include "flowgraph/state_nodes.h"
#include "flowgraph/transitions.h"
#include "tests/flowgraph_graphs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>

namespace plume {
namespace {

using testing::expectInvalid;
using testing::oscillatingGroups;
using testing::params;
using testing::pointers;
using testing::randomCosts;
using testing::walkGraph;

/// Eq. 9-10 in double, term by term, with the rectangle rule over the L samples.
double bruteCost(const PathlineGroup& a, const PathlineGroup& b, double alpha, double beta) {
  double sum = 0.0;
  for (int s = 0; s < a.layout.samples; ++s) {
    double u = 0.0, r = 0.0, t = 0.0;
    for (int x = 0; x < a.layout.particles; ++x) {
      const std::size_t i = a.index(x, s);
      for (int c = 0; c < 3; ++c) u += std::pow(double(a.velocity[i][c]) - double(b.velocity[i][c]), 2);
      r += std::pow(double(a.density[i]) - double(b.density[i]), 2);
      t += std::pow(double(a.temperature[i]) - double(b.temperature[i]), 2);
    }
    const double inv = 1.0 / a.layout.particles;  // (1/|Ω|) Σ_x of eq. 10
    sum += double(a.layout.sampleDt) * (u * inv + alpha * r * inv + beta * t * inv);
  }
  return std::sqrt(sum);
}

TEST(FlowGraphCost, MatchesBruteForceAcrossTilesAndStates) {
  // 70 nodes: three tiles of 32 per side, the last partial; 37 particles (a partial chunk of
  // pathlines) and 19 samples (3L = 57: a partial lane block) exercise every tail.
  const auto groups = oscillatingGroups({40, 30}, 37, 19, 1);
  const CostMatrix c = computeCostMatrix(pointers(groups), params(32));
  ASSERT_EQ(c.size(), 70);
  double worst = 0.0;
  for (int i = 0; i < c.size(); ++i) {
    EXPECT_EQ(c(i, i), 0.0);
    for (int j = 0; j < c.size(); ++j) {
      EXPECT_EQ(c(i, j), c(j, i));
      if (i == j) continue;
      const double ref = bruteCost(groups[std::size_t(i)], groups[std::size_t(j)], 0.7, 1.3);
      worst = std::max(worst, std::fabs(c(i, j) - ref) / ref);
    }
  }
  // Float squares of float differences (≤ 3 roundings each) summed in float over ≤ 36 terms per
  // lane before double: relative error of c² ≤ ~40 float ε ≈ 5e-6, of c half that; 1e-5 leaves
  // margin while a wrong weight, sample or particle would be off by percents.
  EXPECT_LT(worst, 1e-5);
}

TEST(FlowGraphCost, SameBitsAtOneAndTwoThreads) {
  const auto groups = oscillatingGroups({45, 36}, 50, 24, 2);
  const CostMatrix one = computeCostMatrix(pointers(groups), params(32, 1));
  const CostMatrix two = computeCostMatrix(pointers(groups), params(32, 2));
  EXPECT_EQ(one.values(), two.values());
}

TEST(FlowGraphCost, ProgressAndCancel) {
  const auto groups = oscillatingGroups({40, 30}, 8, 6, 2);
  CostMatrixProgress done;
  EXPECT_EQ(computeCostMatrix(pointers(groups), params(32), &done).size(), 70);
  EXPECT_EQ(done.tiles.load(), 6);  // 3 × 3 tiles of 32, upper triangle
  EXPECT_EQ(done.fraction(), 1.0);
  CostMatrixProgress cancelled;
  cancelled.cancel = true;
  EXPECT_EQ(computeCostMatrix(pointers(groups), params(32), &cancelled).size(), 0);
  EXPECT_EQ(cancelled.tilesDone.load(), 0);
}

TEST(FlowGraphCost, RejectsGroupsThatDoNotShareALayout) {
  auto groups = oscillatingGroups({3, 3}, 8, 6, 3);
  for (int k = 3; k < 6; ++k) groups[std::size_t(k)] = oscillatingGroups({3}, 7, 6, 3)[std::size_t(k - 3)];
  for (int k = 3; k < 6; ++k) groups[std::size_t(k)].state = 1;
  expectInvalid([&] { computeCostMatrix(pointers(groups), params(2)); },
                {"state 1 has 7 particles per group, state 0 has 8", "domains or sources differ"});
  auto samples = oscillatingGroups({2, 2}, 8, 6, 3);
  samples[3] = oscillatingGroups({2, 2}, 8, 5, 3)[3];
  expectInvalid([&] { computeCostMatrix(pointers(samples), params(2)); },
                {"group 3 (state 1, step 1) has 5 samples per pathline", "the state's first group has 6"});
  auto order = oscillatingGroups({2, 2}, 4, 4, 3);
  order[2].state = 2;
  expectInvalid([&] { stateNodeCounts(pointers(order)); }, {"group 2", "ordered state by state"});
  auto steps = oscillatingGroups({3}, 4, 4, 3);
  steps[2].step = 5;
  expectInvalid([&] { stateNodeCounts(pointers(steps)); }, {"group 2", "consecutive"});
  auto sizes = oscillatingGroups({2}, 4, 4, 3);
  sizes[1].density.pop_back();
  expectInvalid([&] { stateNodeCounts(pointers(sizes)); }, {"group 1", "15 density samples", "needs 16"});
  expectInvalid([&] { stateNodeCounts({}); }, {"groups"});
}

TEST(FlowGraphCost, FromValuesChecksTheMatrix) {
  EXPECT_NO_THROW(CostMatrix::fromValues(2, {0, 1, 1, 0}));
  expectInvalid([] { CostMatrix::fromValues(2, {0, 1, 2, 0}); }, {"symmetric"});
  expectInvalid([] { CostMatrix::fromValues(2, {1, 1, 1, 0}); }, {"diagonal"});
  expectInvalid([] { CostMatrix::fromValues(2, {0, -1, -1, 0}); }, {">= 0"});
  expectInvalid([] { CostMatrix::fromValues(2, {0, 1, 1}); }, {"3 values"});
}

TEST(FlowGraphParams, ValidateNamesTheSetting) {
  auto bad = [](auto change, const char* name) {
    FlowGraphParams p;
    change(p);
    expectInvalid([&] { p.validate(); }, {name});
  };
  bad([](FlowGraphParams& p) { p.blockSize = 0; }, "block_size");
  bad([](FlowGraphParams& p) { p.blockSize = -3; }, "block_size");
  bad([](FlowGraphParams& p) { p.alpha = -1; }, "alpha");
  bad([](FlowGraphParams& p) { p.beta = NAN; }, "beta");
  bad([](FlowGraphParams& p) { p.minNodeGap = -1; }, "min_node_gap");
  bad([](FlowGraphParams& p) { p.threads = -1; }, "threads");
  bad([](FlowGraphParams& p) {
    p.epsilonMode = EpsilonMode::Explicit;
    p.epsilon = INFINITY;
  }, "epsilon");
  EXPECT_NO_THROW(FlowGraphParams().validate());
}

TEST(FlowGraphParams, SameMagnitudeWeightsAreRatiosOfMeanDifferences) {
  // Two groups differing by a constant: ‖ΔU‖² = |(1, 2, 2)|² = 9, ‖ΔR‖² = 0.5², ‖ΔT‖² = 3².
  auto groups = oscillatingGroups({2}, 5, 4, 4, 0.f);
  for (std::size_t i = 0; i < groups[1].layout.values(); ++i) {
    groups[1].velocity[i] = groups[0].velocity[i] + glm::vec3(1, 2, 2);
    groups[1].density[i] = groups[0].density[i] + 0.5f;
    groups[1].temperature[i] = groups[0].temperature[i] + 3.f;
  }
  const FlowWeights w = sameMagnitudeWeights(pointers(groups));
  // Float sums of float inputs: the differences are exact to ~1e-7 relative.
  EXPECT_NEAR(w.alpha, 9.0 / 0.25, 36.0 * 1e-5);
  EXPECT_NEAR(w.beta, 9.0 / 9.0, 1e-5);
  // With those weights the three terms of eq. 9 are equal: c² = 3 Σ_s Δt_n ‖ΔU‖².
  FlowGraphParams p;
  p.alpha = w.alpha;
  p.beta = w.beta;
  const CostMatrix c = computeCostMatrix(pointers(groups), p);
  EXPECT_NEAR(c(0, 1) * c(0, 1), 3.0 * 4 * (1.0 / 48.0) * 9.0, 1e-4);
}

TEST(FlowGraphTransitions, BlockMinimaAtMostMSquaredAndEpsilon) {
  const CostMatrix c = randomCosts(150, 5);
  const std::vector<int> counts = {60, 50, 40};
  const std::vector<int> offsets = stateOffsets(counts), state = nodeStates(offsets);
  for (int B : {1, 3, 8, 32, 200}) {
    FlowGraphParams p = params(B);
    const TransitionSelection s = selectTransitions(c, counts, p);
    const int M = (150 + B - 1) / B;
    EXPECT_EQ(s.blocksPerSide, M);
    EXPECT_LE(int(s.candidates.size()), M * M);
    EXPECT_LE(s.keptCount(), M * M);
    if (M > 1) EXPECT_GT(s.keptCount(), 0) << "B = " << B;  // one block: a = b, nothing is < ε
    EXPECT_DOUBLE_EQ(s.epsilon, (2 * s.a + s.b) / 3);
    for (const TransitionCandidate& t : s.candidates) {
      EXPECT_TRUE(transitionEligible(t.row, t.col, state, offsets, p.minNodeGap));
      EXPECT_EQ(t.kept, t.cost < s.epsilon);
      EXPECT_GE(t.cost, s.a);
      EXPECT_LE(t.cost, s.b);
      // The minimum of its block over the eligible entries (brute force).
      const int bi = t.row / B, bj = t.col / B;
      for (int i = bi * B; i < std::min(150, bi * B + B); ++i)
        for (int j = bj * B; j < std::min(150, bj * B + B); ++j)
          if (transitionEligible(i, j, state, offsets, p.minNodeGap)) EXPECT_GE(c(i, j), t.cost);
    }
  }
  // Close pairs of one state are never candidates; the same pair across states may be.
  EXPECT_FALSE(transitionEligible(10, 18, state, offsets, 8));
  EXPECT_TRUE(transitionEligible(10, 19, state, offsets, 8));
  EXPECT_FALSE(transitionEligible(11, 10, state, offsets, 0));  // self loop 11 -> 11
  EXPECT_FALSE(transitionEligible(10, 59, state, offsets, 8));  // 59 is the last node of state 0
  EXPECT_TRUE(transitionEligible(59, 60, state, offsets, 8));
}

TEST(FlowGraphTransitions, ExplicitEpsilonMustLieBetweenAAndB) {
  const CostMatrix c = randomCosts(100, 6);
  FlowGraphParams p = params(10);
  const TransitionSelection ref = selectTransitions(c, {100}, p);
  p.epsilonMode = EpsilonMode::Explicit;
  p.epsilon = 0.5 * (ref.a + ref.b);
  const TransitionSelection mid = selectTransitions(c, {100}, p);
  EXPECT_EQ(mid.epsilon, p.epsilon);
  for (const TransitionCandidate& t : mid.candidates) EXPECT_EQ(t.kept, t.cost < p.epsilon);
  p.epsilon = ref.b * 1.01;
  expectInvalid([&] { selectTransitions(c, {100}, p); }, {"epsilon must be in [a, b]"});
  p.epsilon = ref.a * 0.99;
  expectInvalid([&] { selectTransitions(c, {100}, p); }, {"epsilon", "candidate transition costs"});
  expectInvalid([&] { selectTransitions(c, {50, 40}, params(10)); }, {"state_node_counts", "90", "100"});
}

/// A graph with many transitions: three states of random costs, B = 8.

/// Every node left has an out-edge, every edge joins nodes left, temporal edges join k -> k+1.
void expectNoDeadEnd(const FlowGraph& g) {
  for (int n = 0; n < g.nodeCount(); ++n) {
    if (g.pruned(n)) {
      EXPECT_EQ(g.outDegree(n), 0);
      continue;
    }
    EXPECT_GE(g.outDegree(n), 1) << "node " << n;
    for (const FlowEdge& e : g.outEdges(n)) {
      EXPECT_FALSE(g.pruned(e.to));
      EXPECT_NE(e.to, n);
      if (e.temporal) EXPECT_TRUE(e.to == n + 1 && g.state(n) == g.state(e.to));
    }
  }
}

TEST(FlowGraphBuild, RandomCostsHaveNoDeadEnd) {
  for (std::uint64_t seed : {7, 8, 9}) {
    const FlowGraph g = FlowGraph::build(randomCosts(300, seed), {120, 100, 80}, params(16));
    expectNoDeadEnd(g);
    int pruned = 0;
    for (int s = 0; s < 3; ++s) pruned += g.prunedPerState()[std::size_t(s)];
    int counted = 0;
    for (int n = 0; n < 300; ++n) counted += g.pruned(n);
    EXPECT_EQ(pruned, counted);
    // Every kept transition between surviving nodes is an edge row -> col + 1.
    for (const TransitionCandidate& t : g.transitions().candidates) {
      if (!t.kept || g.pruned(t.row) || g.pruned(t.col + 1)) continue;
      bool found = false;
      for (const FlowEdge& e : g.outEdges(t.row)) found |= e.to == t.col + 1 && !e.temporal;
      EXPECT_TRUE(found);
    }
  }
}

/// One state of 20 nodes, B = 10, all costs 1 but c(3, 15) = 0.1: the kept candidates give the
/// edges 3 -> 16 and 15 -> 4, so 4..15 is a loop and 16..19 lead to the dead end 19.
CostMatrix deadEndCosts() {
  CostMatrix c(20);
  for (int i = 0; i < 20; ++i)
    for (int j = i + 1; j < 20; ++j) c.set(i, j, 1.0);
  c.set(3, 15, 0.1);
  return c;
}

TEST(FlowGraphBuild, DeadEndIsPruned) {
  const FlowGraph g = FlowGraph::build(deadEndCosts(), {20}, params(10));
  expectNoDeadEnd(g);
  EXPECT_EQ(g.prunedPerState(), std::vector<int>{4});
  for (int n = 0; n < 20; ++n) EXPECT_EQ(g.pruned(n), n >= 16) << n;
  ASSERT_EQ(g.outDegree(15), 1);  // the temporal edge to the pruned 16 is gone
  EXPECT_EQ(g.outEdges(15).begin()->to, 4);
  EXPECT_FALSE(g.outEdges(15).begin()->temporal);
  EXPECT_EQ(g.outDegree(3), 1);  // 3 -> 16 is gone, 3 -> 4 stays
  for (int n = 0; n < 16; ++n) EXPECT_TRUE(g.staysInState(n));
}

TEST(FlowGraphBuild, TrapIsPruned) {
  // One state of 30 nodes, B = 10, costs 1 but c(3, 15) = c(19, 28) = 0.1: edges 3 -> 16,
  // 15 -> 4 (the loop 4..15, 12 nodes) and 19 -> 29, 28 -> 20 (the loop 20..28, 9 nodes).
  // 29 is a dead end. 15 -> 16 leads into the second loop, whose only exit, 28 -> 29, is the
  // dead end: a walk entering 16 would replay 20..28 forever. The trap 16..28 goes with 29.
  CostMatrix c(30);
  for (int i = 0; i < 30; ++i)
    for (int j = i + 1; j < 30; ++j) c.set(i, j, 1.0);
  c.set(3, 15, 0.1);
  c.set(19, 28, 0.1);
  const FlowGraph g = FlowGraph::build(c, {30}, params(10));
  expectNoDeadEnd(g);
  EXPECT_EQ(g.prunedPerState(), std::vector<int>{14});
  for (int n = 0; n < 30; ++n) EXPECT_EQ(g.pruned(n), n >= 16) << n;
  ASSERT_EQ(g.outDegree(15), 1);
  EXPECT_EQ(g.outEdges(15).begin()->to, 4);
  // Every node left reaches every other one: a walk visits them all.
  RandomWalk walk(g, 5, WalkBias::Uniform, 0.875, 0);
  std::vector<int> visits(30, 0);
  for (int k = 0; k < 20000; ++k) ++visits[std::size_t(walk.next())];
  for (int n = 4; n < 16; ++n) EXPECT_GT(visits[std::size_t(n)], 100) << n;
}

TEST(FlowGraphBuild, ReachableStates) {
  EXPECT_EQ(walkGraph().reachableStates(0), (std::vector<int>{0, 1, 2}));
  // Two copies of the dead-end state, far apart: no transition joins them.
  CostMatrix c(40);
  for (int i = 0; i < 40; ++i)
    for (int j = i + 1; j < 40; ++j) c.set(i, j, (i < 20) == (j < 20) ? 1.0 : 5.0);
  c.set(3, 15, 0.1);
  c.set(23, 35, 0.1);
  const FlowGraph g = FlowGraph::build(c, {20, 20}, params(10));
  EXPECT_EQ(g.reachableStates(0), std::vector<int>{0});
  EXPECT_EQ(g.reachableStates(1), std::vector<int>{1});
  expectInvalid([&] { g.reachableStates(2); }, {"state", "[0, 1]"});
}

TEST(FlowGraphBuild, FirstNodePrunedIsAnError) {
  CostMatrix c(20);
  for (int i = 0; i < 20; ++i)
    for (int j = i + 1; j < 20; ++j) c.set(i, j, 1.0);  // a = b: nothing is kept
  expectInvalid([&] { FlowGraph::build(c, {20}, params(10)); },
                {"first node of state 0", "Add states", "block_size", "epsilon"});
  expectInvalid([&] { FlowGraph::build(c, {20}, params(0)); }, {"block_size"});
}

TEST(FlowGraphImage, Figure4Marks) {
  const FlowGraph g = FlowGraph::build(randomCosts(200, 12), {120, 80}, params(20));
  const CostMatrix c = randomCosts(200, 12);
  const RgbImage img = costMatrixImage(c, g.transitions(), {120, 80}, 400);
  ASSERT_EQ(img.width, 400);
  ASSERT_EQ(img.pixels.size(), 400u * 400u * 3u);
  auto at = [&](int x, int y) {
    const std::uint8_t* p = &img.pixels[(std::size_t(y) * 400 + std::size_t(x)) * 3];
    return std::array<int, 3>{p[0], p[1], p[2]};
  };
  EXPECT_EQ(at(5, 5), (std::array<int, 3>{0, 0, 0}));  // c = 0 on the diagonal: black
  EXPECT_EQ(at(240, 20), (std::array<int, 3>{200, 30, 30}));  // state line at node 120
  int kept = 0, filtered = 0;
  for (const TransitionCandidate& t : g.transitions().candidates) {
    const auto p = at(2 * t.col + 1, 2 * t.row + 1);
    if (t.kept) kept += p == std::array<int, 3>{255, 220, 0};
    else filtered += p == std::array<int, 3>{40, 90, 255} || p == std::array<int, 3>{255, 220, 0};
  }
  EXPECT_EQ(kept, g.transitions().keptCount());
  EXPECT_EQ(filtered, int(g.transitions().candidates.size()) - kept);
  expectInvalid([&] { costMatrixImage(c, g.transitions(), {120, 80}, 0); }, {"size"});
}

}  // namespace
}  // namespace plume
