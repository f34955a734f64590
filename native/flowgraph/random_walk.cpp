/// \file random_walk.cpp
/// Edge probabilities of §5.1 (uniform, eq. 12, target states) and the seeded draw.

#include "flowgraph/random_walk.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

void requireTarget(const FlowGraph& graph, int targetState) {
  if (targetState < -1 || targetState >= graph.stateCount())
    throw std::invalid_argument("target_state must be in [-1, " + std::to_string(graph.stateCount() - 1) +
                                "] (-1: none; got " + std::to_string(targetState) + ")");
}

}  // namespace

RandomWalk::RandomWalk(const FlowGraph& graph, std::uint64_t seed, WalkBias bias, double gamma, int startState)
    : mGraph(&graph), mRng(seed), mBias(bias), mGamma(gamma), mCurrent(0) {
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
  mCurrent = graph.node(startState, 0);
  if (graph.pruned(mCurrent))
    throw std::invalid_argument("start_state " + std::to_string(startState) + ": its first node was pruned");
}

void RandomWalk::probabilities(int node, int targetState, std::vector<double>& p) const {
  const FlowGraph::EdgeRange edges = mGraph->outEdges(node);
  const int d = edges.size();
  p.assign(std::size_t(d), 0.0);
  if (targetState >= 0) {
    // §5.1 target state W: uniform over the edges into W (those that can stay in W first).
    for (bool mustStay : {true, false}) {
      int k = 0;
      for (const FlowEdge& e : edges)
        k += mGraph->state(e.to) == targetState && (!mustStay || mGraph->staysInState(e.to));
      if (k == 0) continue;
      for (int n = 0; n < d; ++n) {
        const FlowEdge& e = edges.first[n];
        if (mGraph->state(e.to) == targetState && (!mustStay || mGraph->staysInState(e.to)))
          p[std::size_t(n)] = 1.0 / k;
      }
      return;
    }
  }
  int temporal = -1;
  for (int n = 0; n < d; ++n)
    if (edges.first[n].temporal) temporal = n;
  if (mBias == WalkBias::Uniform || temporal < 0 || d == 1) {
    for (double& q : p) q = 1.0 / d;
    return;
  }
  for (double& q : p) q = (1.0 - mGamma) / (d - 1);  // eq. 12
  p[std::size_t(temporal)] = mGamma;
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
  probabilities(mCurrent, targetState, mScratch);
  const FlowGraph::EdgeRange edges = mGraph->outEdges(mCurrent);
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
  return mCurrent;
}

}  // namespace plume
