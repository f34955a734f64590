/// \file random_walk.cpp
/// Edge probabilities of §5.1 (uniform, eq. 12, target states) and the seeded draw.

#include "flowgraph/random_walk.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

constexpr int kFar = TargetDistances::kFar;

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
  mTargets = TargetDistances(graph, transitionHold);
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
    // §5.1 target state W: along a shortest path to W' (its distance counting the holds), then
    // staying in W' (see the header), inside it the edges the hold allows first.
    // The strict distance (no hold broken on the way) where it is finite, else the loose one.
    const bool strict = mTargets(targetState, node, 0, true) != kFar;
    const int here = mTargets(targetState, node, 0, strict);
    if (here != kFar) {
      for (bool mustAllow : {true, false}) {
        auto take = [&](const FlowEdge& e) {
          if (here == 0)  // stay in W', the hold that follows a transition kept inside it
            return mTargets.inGoal(targetState, e.to) &&
                   (!mustAllow || e.temporal || mTargets.goalRun(targetState, e.to) >= mHold);
          return mTargets(targetState, e.to, e.temporal ? 0 : mHold, strict) == here - 1;
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

bool RandomWalk::keepsTarget(int from, int to, int holdAfter, int targetState) const {
  if (targetState < 0) return true;
  if (mTargets.inGoal(targetState, from)) return mTargets.inGoal(targetState, to);  // stay in W'
  return mTargets(targetState, from, holdAfter + 1, false) == kFar ||  // on the way: never
         mTargets(targetState, to, holdAfter, false) != kFar;          // where W' is out of reach
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
      if (e.temporal && keepsTarget(mCurrent, e.to, mHoldLeft, targetState)) return mCurrent = e.to;
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
