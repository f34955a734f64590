#pragma once
/// \file flowgraph_graphs.h
/// Shared by the flow-graph graph and walk tests ([Graph Fire Synthesis] §4.3-5.1): the
/// build settings, a three-state graph with many transitions, and the bad-input check.

#include "flowgraph/flow_graph.h"
#include "flowgraph/flow_graph_params.h"
#include "tests/flowgraph_groups.h"

#include <gtest/gtest.h>

#include <functional>
#include <initializer_list>
#include <stdexcept>
#include <string>

namespace plume::testing {

/// Expects fn() to throw std::invalid_argument whose message contains every one of `words`.
inline void expectInvalid(const std::function<void()>& fn, std::initializer_list<const char*> words) {
  try {
    fn();
    ADD_FAILURE() << "no exception; expected one naming " << *words.begin();
  } catch (const std::invalid_argument& e) {
    for (const char* w : words) EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what();
  }
}

/// α = 0.7, β = 1.3, blocks of `blockSize`, ε = (2a + b)/3.
inline FlowGraphParams params(int blockSize, int threads = 0) {
  FlowGraphParams p;
  p.alpha = 0.7;
  p.beta = 1.3;
  p.blockSize = blockSize;
  p.threads = threads;
  return p;
}

/// Three states of 140, 120 and 100 nodes, B = 8: many transitions between and inside states.
inline FlowGraph walkGraph() { return FlowGraph::build(randomCosts(360, 11), {140, 120, 100}, params(8)); }

}  // namespace plume::testing
