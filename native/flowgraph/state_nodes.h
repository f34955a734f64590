#pragma once
/// \file state_nodes.h
/// The node order of a flow graph ([Graph Fire Synthesis] §4.3): the pathline groups of every
/// state, state by state, each state's groups chronologically ("we order the nodes
/// chronologically"), all sharing one PathlineLayout so that eq. 10 compares like with like.

#include "flowgraph/pathline_group.h"

#include <vector>

namespace plume {

/// Checks that the groups form a valid node list and returns the node count of each state.
/// Throws std::invalid_argument naming the offending group or state when: there is no group; a
/// pointer is null; a layout has no particles or samples, or a node step that is not a positive
/// finite number; the groups do not share one layout (e.g. "state 1 has 3000 particles per group,
/// state 0 has 3217: the states' domains or sources differ"); a group's arrays do not match its
/// layout; states are not numbered 0, 1, 2, ... in order; or a state's steps are not consecutive.
std::vector<int> stateNodeCounts(const std::vector<const PathlineGroup*>& groups);

/// Throws std::invalid_argument with the message stateNodeCounts() gives (e.g. "state 1 has 3000
/// particles per group, state 0 has 3217: ...") unless `layout`, state `state`'s, equals `first`,
/// state 0's.
void requireStateLayout(int state, const PathlineLayout& layout, const PathlineLayout& first);

/// Checks counts (one positive node count per state, at least one state, total below 2^31) and
/// returns the index of each state's first node, plus the total as last element (eq. 8 nodes).
std::vector<int> stateOffsets(const std::vector<int>& counts);

/// The state of every node, from stateOffsets().
std::vector<int> nodeStates(const std::vector<int>& offsets);

}  // namespace plume
