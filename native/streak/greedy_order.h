#pragma once
/// \file greedy_order.h
/// The order of a surface's streaklines across the surface ([Smoke Surfaces] §3.3, Figure 5):
/// the greedy approximation of the minimum-length connection, from sparse distances.

#include "streak/streak_distances.h"

#include <vector>

namespace plume {

/// §3.3 (Figure 5): greedy minimum-length ordering of a surface's streaklines. Starts from the
/// pair (α, β) with the smallest h among `members`, then repeatedly adds the source γ minimising
/// h(γ, end) over both ends of the chain and attaches it at that end. Ties go to the earlier
/// member (in the order given) and to the front end. Returns `members` reordered, exactly as
/// the same rule over all pairs would (bruteForceOrder). The nearest remaining member of an
/// end comes from its held pairs when one is left (all pairs with h < reach are held); else
/// every remaining member is ranked by the projection bound and exact h is computed in that
/// order until the bound proves the rest farther. O(k²) bounds at worst for k members, never
/// O(n²). Throws std::invalid_argument on an index out of range or a repeated member.
std::vector<int> orderGreedy(const StreakDistances& h, const std::vector<int>& members);

}  // namespace plume
