/// \file random_walk.cpp
/// Edge probabilities of §5.1 (uniform, eq. 12, target states) and the seeded draw.

#include "flowgraph/random_walk.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <sstream>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

constexpr int kFar = std::numeric_limits<int>::max();

/// δ(n): fewest edges from every node to the goal W' of `state` (see edgeProbabilities()), by a
/// breadth-first search backwards from W'.
std::vector<int> distancesTo(const FlowGraph& graph, int state, const std::vector<std::vector<int>>& into) {
  std::vector<int> goal;
  for (bool mustStay : {true, false}) {
    for (int step = 0; step < graph.stateNodeCount(state); ++step) {
      const int n = graph.node(state, step);
      if (!graph.pruned(n) && (!mustStay || graph.staysInState(n))) goal.push_back(n);
    }
    if (!goal.empty()) break;
  }
  std::vector<int> dist(std::size_t(graph.nodeCount()), kFar);
  std::queue<int> open;
  for (int n : goal) {
    dist[std::size_t(n)] = 0;
    open.push(n);
  }
  while (!open.empty()) {
    const int n = open.front();
    open.pop();
    for (int from : into[std::size_t(n)])
      if (dist[std::size_t(from)] == kFar) {
        dist[std::size_t(from)] = dist[std::size_t(n)] + 1;
        open.push(from);
      }
  }
  return dist;
}

void requireTarget(const FlowGraph& graph, int targetState) {
  if (targetState < -1 || targetState >= graph.stateCount())
    throw std::invalid_argument("target_state must be in [-1, " + std::to_string(graph.stateCount() - 1) +
                                "] (-1: none; got " + std::to_string(targetState) + ")");
}

}  // namespace

RandomWalk::RandomWalk(const FlowGraph& graph, std::uint64_t seed, WalkBias bias, double gamma, int startState,
                       int transitionHold)
    : mGraph(&graph), mRng(seed), mBias(bias), mGamma(gamma), mCurrent(0), mHold(transitionHold) {
  if (graph.nodeCount() == 0) throw std::invalid_argument("graph: the flow graph has no node (build it first)");
  if (startState < 0 || startState >= graph.stateCount())
    throw std::invalid_argument("start_state must be in [0, " + std::to_string(graph.stateCount() - 1) + "] (got " +
                                std::to_string(startState) + ")");
  if (!(gamma >= 0.0 && gamma <= 1.0)) {
    std::ostringstream m;
    m << "gamma must be in [0, 1], the probability of following the temporal edge (eq. 12) (got " << gamma << ")";
    throw std::invalid_argument(m.str());
  }
  if (bias != WalkBias::Uniform && bias != WalkBias::Temporal)
    throw std::invalid_argument("bias must be UNIFORM or TEMPORAL");
  int shortest = graph.stateNodeCount(0);
  for (int s = 1; s < graph.stateCount(); ++s) shortest = std::min(shortest, graph.stateNodeCount(s));
  if (transitionHold < 0 || transitionHold > shortest - 1)
    throw std::invalid_argument("transition_hold must be in [0, " + std::to_string(shortest - 1) +
                                "] node steps, less than the shortest state's " + std::to_string(shortest) +
                                " nodes (got " + std::to_string(transitionHold) + ")");
  // Temporal runs, from the end of each state backwards: run(n) = run(n + 1) + 1 along a
  // temporal edge n -> n + 1, 0 where the time line ends.
  mRun.assign(std::size_t(graph.nodeCount()), 0);
  for (int n = graph.nodeCount() - 1; n >= 0; --n)
    for (const FlowEdge& e : graph.outEdges(n))
      if (e.temporal) mRun[std::size_t(n)] = mRun[std::size_t(e.to)] + 1;
  std::vector<std::vector<int>> into(std::size_t(graph.nodeCount()));
  for (int n = 0; n < graph.nodeCount(); ++n)
    for (const FlowEdge& e : graph.outEdges(n)) into[std::size_t(e.to)].push_back(n);
  for (int s = 0; s < graph.stateCount(); ++s) mDistance.push_back(distancesTo(graph, s, into));
  mCurrent = graph.node(startState, 0);
  if (graph.pruned(mCurrent))
    throw std::invalid_argument("start_state " + std::to_string(startState) + ": its first node was pruned");
}

void RandomWalk::probabilities(int node, int targetState, std::vector<double>& p) const {
  const FlowGraph::EdgeRange edges = mGraph->outEdges(node);
  const int all = edges.size();
  p.assign(std::size_t(all), 0.0);
  // The edges a free step may take: under a hold, not the short transitions (unless all are).
  int longEdges = 0;
  for (const FlowEdge& e : edges) longEdges += longEnough(e);
  const bool filter = mHold > 0 && longEdges > 0;
  auto allowed = [&](const FlowEdge& e) { return !filter || longEnough(e); };
  if (targetState >= 0) {
    // §5.1 target state W: along a shortest path to W', then staying in it (see the header);
    // edges the hold allows first (reaching W matters more than one shortened hold).
    const std::vector<int>& dist = mDistance[std::size_t(targetState)];
    const int here = dist[std::size_t(node)];
    if (here != kFar) {
      const int want = here == 0 ? 0 : here - 1;
      for (bool mustAllow : {true, false}) {
        auto take = [&](const FlowEdge& e) {
          return (!mustAllow || allowed(e)) && dist[std::size_t(e.to)] == want;
        };
        int k = 0;
        for (const FlowEdge& e : edges) k += take(e);
        if (k == 0) continue;
        if (here == 0) {
          biased(edges, take, p);
        } else {
          for (int n = 0; n < all; ++n)
            if (take(edges.first[n])) p[std::size_t(n)] = 1.0 / k;
        }
        return;
      }
    }
  }
  biased(edges, allowed, p);
}

template <class Take>
void RandomWalk::biased(const FlowGraph::EdgeRange& edges, const Take& take, std::vector<double>& p) const {
  const int all = edges.size();
  int d = 0, temporal = -1;
  for (int n = 0; n < all; ++n) {
    if (!take(edges.first[n])) continue;
    ++d;
    if (edges.first[n].temporal) temporal = n;
  }
  for (int n = 0; n < all; ++n) {
    if (!take(edges.first[n])) continue;
    if (mBias == WalkBias::Uniform || temporal < 0 || d == 1)
      p[std::size_t(n)] = 1.0 / d;
    else  // eq. 12
      p[std::size_t(n)] = n == temporal ? mGamma : (1.0 - mGamma) / (d - 1);
  }
}

bool RandomWalk::keepsTarget(int from, int to, int targetState) const {
  if (targetState < 0) return true;
  const std::vector<int>& dist = mDistance[std::size_t(targetState)];
  const int here = dist[std::size_t(from)], there = dist[std::size_t(to)];
  if (here == 0) return there == 0;          // inside W': stay in it
  return here == kFar || there != kFar;      // on the way: never where W' is out of reach
}

std::vector<double> RandomWalk::edgeProbabilities(int node, int targetState) const {
  if (node < 0 || node >= mGraph->nodeCount())
    throw std::invalid_argument("node must be in [0, " + std::to_string(mGraph->nodeCount() - 1) + "] (got " +
                                std::to_string(node) + ")");
  requireTarget(*mGraph, targetState);
  std::vector<double> p;
  probabilities(node, targetState, p);
  return p;
}

int RandomWalk::next(int targetState) {
  requireTarget(*mGraph, targetState);
  const FlowGraph::EdgeRange edges = mGraph->outEdges(mCurrent);
  if (mHoldLeft > 0) {  // the transition state: the temporal edge, no draw
    --mHoldLeft;
    for (const FlowEdge& e : edges)
      if (e.temporal && keepsTarget(mCurrent, e.to, targetState)) return mCurrent = e.to;
    ++mForced;  // the time line ends here, or leaves the target: a transition after all (below)
  }
  probabilities(mCurrent, targetState, mScratch);
  // One uniform draw per step; the last edge with p > 0 takes what rounding leaves above Σ p.
  const double u = mRng.uniform();
  double sum = 0.0;
  int chosen = -1;
  for (int n = 0; n < edges.size(); ++n) {
    if (mScratch[std::size_t(n)] <= 0.0) continue;
    chosen = n;
    sum += mScratch[std::size_t(n)];
    if (u < sum) break;
  }
  mCurrent = edges.first[chosen].to;  // the graph is pruned: every node has an out-edge
  if (!edges.first[chosen].temporal) mHoldLeft = mHold;
  return mCurrent;
}

}  // namespace plume
