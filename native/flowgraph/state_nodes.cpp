/// \file state_nodes.cpp
/// Checks of the node list of a flow graph (§4.3): one layout for all groups, states in order,
/// consecutive steps, arrays of the layout's size.

#include "flowgraph/state_nodes.h"

#include "core/format.h"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

std::string describe(std::size_t n, const PathlineGroup& g) {
  return "group " + std::to_string(n) + " (state " + std::to_string(g.state) + ", step " +
         std::to_string(g.step) + ")";
}

std::string seconds(float v) { return formatNumber(v) + " s"; }

/// "<who> has <a> <noun>, <other> has <b>: <why>" when layout a differs from b.
void requireLayout(const std::string& who, const PathlineLayout& a, const std::string& other,
                   const PathlineLayout& b) {
  if (a.particles != b.particles)
    throw std::invalid_argument(who + " has " + std::to_string(a.particles) + " particles per group, " +
                                other + " has " + std::to_string(b.particles) +
                                ": the states' domains or sources differ");
  if (a.samples != b.samples)
    throw std::invalid_argument(who + " has " + std::to_string(a.samples) + " samples per pathline, " +
                                other + " has " + std::to_string(b.samples) +
                                ": the states' pathline lifetimes or node steps differ");
  if (a.sampleDt != b.sampleDt)
    throw std::invalid_argument(who + " has node step " + seconds(a.sampleDt) + ", " + other + " has " +
                                seconds(b.sampleDt) + ": the states' frame rates or nodes per frame differ");
}

/// "state 1 has <a> <noun>, state 0 has <b>: <why>" when a state's layout differs from state 0's;
/// "group n (...) has <a> <noun>, the state's first group has <b>" inside one state.
void requireSameLayout(std::size_t n, const PathlineGroup& g, const PathlineGroup& first,
                       const PathlineGroup& stateFirst) {
  // A state's first group against group 0, the others against their state's first group.
  const bool opensState = &g == &stateFirst;
  const PathlineGroup& ref = opensState ? first : stateFirst;
  const std::string who = opensState ? "state " + std::to_string(g.state) : describe(n, g);
  const std::string other = opensState ? "state " + std::to_string(ref.state) : "the state's first group";
  requireLayout(who, g.layout, other, ref.layout);
}

void requireArrays(std::size_t n, const PathlineGroup& g) {
  const std::size_t values = g.layout.values();
  auto check = [&](const char* name, std::size_t got, std::size_t want) {
    if (got != want)
      throw std::invalid_argument(describe(n, g) + " holds " + std::to_string(got) + " " + name + ", its layout (" +
                                  std::to_string(g.layout.particles) + " particles x " +
                                  std::to_string(g.layout.samples) + " samples) needs " + std::to_string(want));
  };
  check("start points", g.start.size(), std::size_t(g.layout.particles));
  check("velocity samples", g.velocity.size(), values);
  check("density samples", g.density.size(), values);
  check("temperature samples", g.temperature.size(), values);
}

}  // namespace

std::vector<int> stateNodeCounts(const std::vector<const PathlineGroup*>& groups) {
  if (groups.empty()) throw std::invalid_argument("groups: a flow graph needs at least one pathline group");
  if (groups.size() > std::size_t(INT32_MAX))
    throw std::invalid_argument("groups: more than 2^31 - 1 pathline groups");
  std::vector<int> counts;
  const PathlineGroup* first = groups.front();
  const PathlineGroup* stateFirst = first;
  for (std::size_t n = 0; n < groups.size(); ++n) {
    const PathlineGroup* g = groups[n];
    if (!g) throw std::invalid_argument("group " + std::to_string(n) + " is missing (null)");
    const PathlineLayout& l = g->layout;
    if (l.particles < 1 || l.samples < 1)
      throw std::invalid_argument(describe(n, *g) + " has " + std::to_string(l.particles) + " particles and " +
                                  std::to_string(l.samples) + " samples: a group needs at least one of each");
    if (!(l.sampleDt > 0.f) || !std::isfinite(l.sampleDt))
      throw std::invalid_argument(describe(n, *g) + " has node step " + seconds(l.sampleDt) +
                                  ": it must be a positive number of seconds");
    const PathlineGroup* prev = n ? groups[n - 1] : nullptr;
    if (prev && g->state == prev->state) {
      if (g->step != prev->step + 1)
        throw std::invalid_argument(describe(n, *g) + " follows step " + std::to_string(prev->step) +
                                    ": the steps of a state must be consecutive");
    } else if (g->state == (prev ? prev->state + 1 : 0)) {
      counts.push_back(0);
      stateFirst = g;
    } else {
      throw std::invalid_argument(describe(n, *g) + (prev ? " follows state " + std::to_string(prev->state)
                                                           : std::string(" comes first")) +
                                  ": groups must be ordered state by state, states numbered 0, 1, 2, ... "
                                  "without gaps");
    }
    requireSameLayout(n, *g, *first, *stateFirst);
    requireArrays(n, *g);
    ++counts.back();
  }
  return counts;
}

void requireStateLayout(int state, const PathlineLayout& layout, const PathlineLayout& first) {
  requireLayout("state " + std::to_string(state), layout, "state 0", first);
}

std::vector<int> stateOffsets(const std::vector<int>& counts) {
  if (counts.empty()) throw std::invalid_argument("state_node_counts: a flow graph needs at least one state");
  std::vector<int> offsets(counts.size() + 1, 0);
  std::int64_t total = 0;
  for (std::size_t s = 0; s < counts.size(); ++s) {
    if (counts[s] < 1)
      throw std::invalid_argument("state_node_counts: state " + std::to_string(s) + " has " +
                                  std::to_string(counts[s]) + " nodes, it needs at least 1");
    offsets[s] = int(total);
    total += counts[s];
    if (total > INT32_MAX) throw std::invalid_argument("state_node_counts: more than 2^31 - 1 nodes in all");
  }
  offsets.back() = int(total);
  return offsets;
}

std::vector<int> nodeStates(const std::vector<int>& offsets) {
  std::vector<int> state(std::size_t(offsets.back()));
  for (std::size_t s = 0; s + 1 < offsets.size(); ++s)
    for (int n = offsets[s]; n < offsets[s + 1]; ++n) state[std::size_t(n)] = int(s);
  return state;
}

}  // namespace plume
