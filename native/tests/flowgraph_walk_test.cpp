/// \file flowgraph_walk_test.cpp
/// Random walks on the flow graph ([Graph Fire Synthesis] §5.1): eq. 12 against its formula,
/// uniform and target-state walks, the transition state (§5: no transition until the particles
/// of the last one have died), seeds and the errors on bad input.

#include "flowgraph/flow_graph.h"
#include "flowgraph/random_walk.h"
#include "tests/flowgraph_graphs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <utility>
#include <vector>

namespace plume {
namespace {

using testing::expectInvalid;
using testing::params;
using testing::randomCosts;
using testing::walkGraph;

/// Eq. 12 written out: the probability of edge e of `node`, with γ and d = d(V_i) counted here
/// from the graph, not from the walk: γ for the temporal edge, (1 − γ)/(d − 1) for each
/// transition; a node without temporal edge, or with d = 1, spreads 1 evenly (1/d).
double equation12(const FlowGraph& g, int node, const FlowEdge& e, double gamma) {
  const int d = g.outDegree(node);
  bool hasTemporal = false;
  for (const FlowEdge& f : g.outEdges(node)) hasTemporal |= f.temporal;
  if (!hasTemporal || d == 1) return 1.0 / d;
  return e.temporal ? gamma : (1.0 - gamma) / (d - 1);
}

TEST(FlowGraphWalk, Equation12PerEdge) {
  const FlowGraph g = walkGraph();
  const double gamma = 0.875;
  RandomWalk walk(g, 42, WalkBias::Temporal, gamma, 0);
  // The walk's own probabilities agree with the formula on every node.
  for (int n = 0; n < g.nodeCount(); ++n) {
    if (g.pruned(n)) continue;
    const std::vector<double> p = walk.edgeProbabilities(n);
    int e = 0;
    for (const FlowEdge& edge : g.outEdges(n)) EXPECT_DOUBLE_EQ(p[std::size_t(e++)], equation12(g, n, edge, gamma));
  }
  // The draws follow the formula. Over 10^5 steps, the edges are pooled by their eq. 12
  // probability p (γ, or (1 − γ)/(d − 1) for each d): the times edges of one class were taken
  // against Σ n_i p over the visits n_i of their nodes, within 4σ, σ² = Σ n_i p (1 − p)
  // (independent Bernoulli draws given the nodes visited).
  const int steps = 100000;
  std::map<int, int> visits;
  std::map<std::pair<int, int>, int> taken;
  int temporal = 0;
  for (int k = 0; k < steps; ++k) {
    const int from = walk.current();
    const int to = walk.next();
    ++visits[from];
    ++taken[{from, to}];
    for (const FlowEdge& e : g.outEdges(from)) temporal += e.to == to && e.temporal;
  }
  struct Pool { double observed = 0, expected = 0, variance = 0; };
  std::map<double, Pool> pools;
  for (const auto& [node, n] : visits)
    for (const FlowEdge& e : g.outEdges(node)) {
      const double p = equation12(g, node, e, gamma);
      Pool& pool = pools[p];
      pool.observed += taken[{node, e.to}];
      pool.expected += n * p;
      pool.variance += n * p * (1.0 - p);
    }
  int checked = 0;
  for (const auto& [p, pool] : pools) {
    if (pool.expected < 100.0) continue;
    ++checked;
    EXPECT_NEAR(pool.observed, pool.expected, 4.0 * std::sqrt(pool.variance)) << "edges of p = " << p;
  }
  EXPECT_GE(checked, 4);  // γ and several (1 − γ)/(d − 1)
  EXPECT_GT(double(temporal) / steps, 0.8);  // most nodes have a temporal edge and d > 1
}

TEST(FlowGraphWalk, UniformIsOneOverDegree) {
  const FlowGraph g = walkGraph();
  RandomWalk walk(g, 42, WalkBias::Uniform, 0.875, 0);
  for (int n = 0; n < g.nodeCount(); ++n)
    for (double p : walk.edgeProbabilities(n)) EXPECT_DOUBLE_EQ(p, 1.0 / g.outDegree(n));
}

/// Steps k at which the walk took a transition (an edge that is not temporal).
std::vector<long long> transitionSteps(const FlowGraph& g, RandomWalk& walk, long long steps,
                                       const std::function<int(long long)>& target) {
  std::vector<long long> at;
  for (long long k = 0; k < steps; ++k) {
    const int from = walk.current();
    const int to = walk.next(target(k));
    bool temporal = false;
    for (const FlowEdge& e : g.outEdges(from)) temporal |= e.to == to && e.temporal;
    if (!temporal) at.push_back(k);
  }
  return at;
}

TEST(FlowGraphWalk, TransitionStateHoldsForTheLifetime) {
  // §5: after a transition the synthesizer stays in the transition state until the particles
  // emitted before it have died, L node steps: no two transitions closer than L.
  const FlowGraph g = walkGraph();
  const int lifetime = 24;
  for (WalkBias bias : {WalkBias::Uniform, WalkBias::Temporal}) {
    RandomWalk walk(g, 7, bias, 0.5, 0, lifetime);
    const std::vector<long long> at = transitionSteps(g, walk, 100000, [](long long) { return -1; });
    ASSERT_GT(at.size(), 1000u);  // the walk does move between time lines
    long long closest = 1 << 30;
    for (std::size_t k = 1; k < at.size(); ++k) closest = std::min(closest, at[k] - at[k - 1]);
    EXPECT_GT(closest, lifetime);
    EXPECT_EQ(walk.forcedTransitions(), 0);
    // Without the hold the same walk jumps again within the lifetime.
    RandomWalk free(g, 7, bias, 0.5, 0, 0);
    const std::vector<long long> loose = transitionSteps(g, free, 100000, [](long long) { return -1; });
    long long closestFree = 1 << 30;
    for (std::size_t k = 1; k < loose.size(); ++k) closestFree = std::min(closestFree, loose[k] - loose[k - 1]);
    EXPECT_LE(closestFree, lifetime);
  }
}

TEST(FlowGraphWalk, TransitionStateStillReachesTheTarget) {
  // Keyed targets 2, 1, 0, 2 for 5,000 steps each: every one is reached and kept, and the
  // transitions the steering takes still keep the hold.
  const FlowGraph g = walkGraph();
  const int lifetime = 24;
  RandomWalk walk(g, 3, WalkBias::Temporal, 0.875, 0, lifetime);
  const int targets[] = {2, 1, 0, 2};
  std::vector<int> visited;
  const std::vector<long long> at = transitionSteps(g, walk, 20000, [&](long long k) {
    visited.push_back(walk.current());
    return targets[k / 5000];
  });
  for (int t = 0; t < 4; ++t) {
    int reached = -1;
    for (int k = 1; k < 5000; ++k) {
      const int n = t * 5000 + k < 20000 ? visited[std::size_t(t * 5000 + k)] : walk.current();
      if (reached < 0 && g.state(n) == targets[t]) reached = k;
      if (reached >= 0) EXPECT_EQ(g.state(n), targets[t]) << "left state " << targets[t] << " at step " << k;
    }
    EXPECT_GE(reached, 0) << "state " << targets[t] << " never reached";
  }
  for (std::size_t k = 1; k < at.size(); ++k) EXPECT_GT(at[k] - at[k - 1], lifetime);
  EXPECT_EQ(walk.forcedTransitions(), 0);
}

TEST(FlowGraphWalk, TargetIsReachedAlongAShortestPath) {
  // §5.1: the probabilities depend on how far the node is from the target state. Steered,
  // every step brings the walk one edge nearer: it reaches W' in exactly δ(start) steps, from
  // wherever an unsteered walk left it (200 trials, each target state).
  const FlowGraph g = walkGraph();
  RandomWalk walk(g, 11, WalkBias::Temporal, 0.875, 0);
  int far = 0;
  for (int trial = 0; trial < 200; ++trial) {
    for (int k = 0; k < 37; ++k) walk.next();
    const int target = trial % 3;
    const int start = walk.current();
    const int delta = walk.targetDistance(start, target);
    ASSERT_GE(delta, 0);
    far = std::max(far, delta);
    for (int k = 0; k < delta; ++k) {
      walk.next(target);
      EXPECT_EQ(walk.targetDistance(walk.current(), target), delta - k - 1);
    }
    EXPECT_EQ(g.state(walk.current()), target);
  }
  EXPECT_GE(far, 2);  // some starts were more than one edge away
}

TEST(FlowGraphWalk, TargetIsReachedAcrossHolds) {
  // With the transition state, the distance counts the holds (target_distance.h): a steered
  // walk still reaches W' in exactly D(start, h) node steps, its transitions spaced by the hold.
  const FlowGraph g = walkGraph();
  const int hold = 12;
  RandomWalk walk(g, 5, WalkBias::Temporal, 0.875, 0, hold);
  long long forcedBefore = 0;
  for (int trial = 0; trial < 150; ++trial) {
    for (int k = 0; k < 41; ++k) walk.next();
    const int target = trial % 3;
    const int delta = walk.targetDistance(walk.current(), target, walk.holdRemaining());
    ASSERT_GE(delta, 0);
    for (int k = 0; k < delta; ++k) {
      walk.next(target);
      EXPECT_EQ(walk.targetDistance(walk.current(), target, walk.holdRemaining()), delta - k - 1);
    }
    EXPECT_EQ(g.state(walk.current()), target);
  }
  EXPECT_EQ(walk.forcedTransitions(), forcedBefore);
}

TEST(FlowGraphWalk, TemporalRuns) {
  const FlowGraph g = walkGraph();
  RandomWalk walk(g, 1);
  for (int n = 0; n < g.nodeCount(); ++n) {
    int run = 0;
    for (int m = n; !g.pruned(m);) {
      int next = -1;
      for (const FlowEdge& e : g.outEdges(m))
        if (e.temporal) next = e.to;
      if (next < 0) break;
      ++run;
      m = next;
    }
    EXPECT_EQ(walk.temporalRun(n), run) << n;
  }
}

TEST(FlowGraphWalk, SameSeedSameWalk) {
  const FlowGraph g = walkGraph();
  RandomWalk a(g, 5, WalkBias::Temporal, 0.5), b(g, 5, WalkBias::Temporal, 0.5), c(g, 6, WalkBias::Temporal, 0.5);
  bool differs = false;
  for (int k = 0; k < 2000; ++k) {
    const int target = (k / 500) % 2 ? 2 : -1;
    const int na = a.next(target);
    EXPECT_EQ(na, b.next(target));
    differs |= na != c.next(target);
  }
  EXPECT_TRUE(differs);
}

TEST(FlowGraphWalk, TargetStateIsReachedAndKept) {
  const FlowGraph g = walkGraph();
  RandomWalk walk(g, 3, WalkBias::Temporal, 0.875, 0);
  for (int target : {2, 1, 0}) {
    int reached = -1;
    for (int k = 0; k < 5000; ++k) {
      const int n = walk.next(target);
      if (reached < 0 && g.state(n) == target) reached = k;
      if (reached >= 0) EXPECT_EQ(g.state(n), target) << "left state " << target << " at step " << k;
    }
    EXPECT_GE(reached, 0) << "state " << target << " never reached";
  }
}

TEST(FlowGraphWalk, TargetPrefersNodesThatCanStay) {
  // States A = 0..19 and B = 20..39, B = 10: costs 3 inside a state, 5 across, 0.1 on the pairs
  // giving the edges 15 -> 4 (loop in A), 35 -> 24 (loop in B), 23 -> 36 (into B's tail),
  // 5 -> 37, 36 -> 6 and 39 -> 13 (between the states). A's tail 16..19 is pruned; B's tail
  // 36..39 survives (39 -> 13) but cannot stay in B.
  CostMatrix c(40);
  for (int i = 0; i < 40; ++i)
    for (int j = i + 1; j < 40; ++j) c.set(i, j, (i < 20) == (j < 20) ? 3.0 : 5.0);
  for (auto [i, j] : {std::pair{3, 15}, {23, 35}, {5, 36}, {39, 12}}) c.set(i, j, 0.1);
  const FlowGraph g = FlowGraph::build(c, {20, 20}, params(10));
  EXPECT_EQ(g.prunedPerState(), (std::vector<int>{4, 0}));
  for (int n = 20; n < 40; ++n) EXPECT_EQ(g.staysInState(n), n < 36) << n;
  RandomWalk walk(g, 9, WalkBias::Uniform, 0.875, 1);
  EXPECT_EQ(walk.edgeProbabilities(23), (std::vector<double>{0.5, 0.5}));    // 24, 36
  EXPECT_EQ(walk.edgeProbabilities(23, 1), (std::vector<double>{1.0, 0.0}));  // only 24 stays
  for (int k = 0; k < 10000; ++k) {
    const int n = walk.next(1);
    ASSERT_TRUE(n >= 20 && n < 36) << "step " << k << " visited " << n;
  }
}

TEST(FlowGraphWalk, BadInputsNameTheSetting) {
  const FlowGraph g = walkGraph();
  expectInvalid([&] { RandomWalk(g, 1, WalkBias::Temporal, 1.5); }, {"gamma"});
  expectInvalid([&] { RandomWalk(g, 1, WalkBias::Temporal, 0.5, 3); }, {"start_state", "[0, 2]"});
  RandomWalk w(g, 1);
  expectInvalid([&] { w.next(3); }, {"target_state", "[-1, 2]"});
  expectInvalid([&] { w.edgeProbabilities(360); }, {"node"});
  // A hold as long as the shortest state (100 nodes) could never end inside it.
  expectInvalid([&] { RandomWalk(g, 1, WalkBias::Temporal, 0.5, 0, 100); }, {"transition_hold", "[0, 99]"});
  expectInvalid([&] { RandomWalk(g, 1, WalkBias::Temporal, 0.5, 0, -1); }, {"transition_hold"});
}

}  // namespace
}  // namespace plume
