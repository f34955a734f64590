#pragma once
/// \file candidate_pairs.h
/// The pairs of a candidate group that can share a surface ([Smoke Surfaces] §3.3), found
/// without visiting all n²/2 pairs: a uniform grid over three projected coordinates proposes
/// neighbours, the projection bound discards most, exact h decides the rest.

#include "streak/streak_group.h"
#include "streak/streak_projection.h"

#include <cstdint>
#include <vector>

namespace plume {

/// Two members of a group (a < b) and their distance h(a, b) (§3.3).
struct DistancePair {
  int a = 0;
  int b = 0;
  double h = 0.0;
};

/// How much work the pair search of §3.3 did (for benchmarks and reports; not part of the result).
struct CandidateStats {
  std::uint64_t examined = 0;  ///< pairs in neighbouring grid cells
  std::uint64_t exact = 0;     ///< pairs the bound left: h computed (maybe stopped early)
  std::uint64_t kept = 0;      ///< pairs with h < reach
};

/// Result of findCandidatePairs() (§3.3).
struct CandidatePairs {
  std::vector<DistancePair> pairs;  ///< sorted by (a, b)
  CandidateStats stats;
};

/// §3.3: every pair of members with h(α,β) < reach, each with h exactly as streakDistance()
/// computes it, sorted by (a, b); reach = +inf keeps all pairs, reach <= 0 none. A pair is
/// discarded only when its projection bound L satisfies L >= reach + slack(reach), which proves
/// h >= reach, so the set equals the brute-force set {h < reach} exactly. Grid cells have side
/// √(reach + slack): a pair closer than that in the first three projected coordinates lies in
/// the same or adjacent cells. Parallel over members, merged in a fixed order: the result and
/// the stats do not depend on the thread count. Throws std::invalid_argument if reach is NaN or
/// the projection is not of this group.
CandidatePairs findCandidatePairs(const StreakGroup& g, const StreakProjection& q, double reach);

}  // namespace plume
