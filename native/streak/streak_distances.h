#pragma once
/// \file streak_distances.h
/// The distances h(α,β) of one candidate group ([Smoke Surfaces] §3.3), sparse: every pair
/// with h below a reach (by default the default threshold h0, the mean of h), exactly, in
/// O(pairs) memory instead of an n × n matrix; h of any other pair on demand.

#include "streak/candidate_pairs.h"
#include "streak/streak_group.h"
#include "streak/streak_projection.h"

#include <cstddef>
#include <memory>
#include <vector>

namespace plume {

/// §3.3: what StreakDistances keeps.
struct DistanceParams {
  /// Keep every pair with h < reach (+inf: all pairs). < 0: the default h0 (the mean of h).
  double reach = -1.0;
  ProjectionParams projection;
  /// Throws std::invalid_argument if reach is NaN or the projection parameters are out of range.
  void validate() const;
};

/// §3.3 Figure 4: number of surfaces and of the streaklines they use for one threshold h0.
struct ClusterSummary {
  int surfaces = 0;
  int streaklines = 0;
};

/// §3.3 Figure 4 as a step function of h0: single linkage (Kruskal over the pairs sorted by h)
/// joins sets only at values of h, so the counts are constant between them.
struct ThresholdCurve {
  std::vector<double> values;           ///< ascending, distinct: the h where the counts change
  std::vector<ClusterSummary> counts;   ///< with every pair of h <= values[k] joined
  /// The counts for threshold h0 (pairs with h < h0 joined).
  ClusterSummary at(double h0) const;
};

/// §3.3: the distances of one candidate group, sparse and exact below the reach: the pairs with
/// h(α,β) < reach() (h exactly as streakDistance() computes it), as symmetric adjacency lists,
/// the (h0 → surfaces, streaklines) curve they give for every h0 <= reach(), and the default
/// h0. Immutable once built, so it can be read from several threads.
class StreakDistances {
 public:
  /// Throws std::invalid_argument on bad params, or when the default reach (the mean of h) is
  /// asked for a group of fewer than 2 sources.
  explicit StreakDistances(StreakGroup group, const DistanceParams& params = {});
  /// The same group for another reach (>= 0 or +inf), reusing the mean and the projection.
  StreakDistances withReach(double reach) const;

  const StreakGroup& group() const { return mGroup; }
  int size() const { return mGroup.size(); }
  /// §3.3 default h0, the mean of h over the pairs α < β (centred sums, streakMoments()).
  /// Throws std::invalid_argument for fewer than 2 sources.
  double meanDistance() const;
  /// Every pair with h < reach() is held; pairs with h >= reach() are not.
  double reach() const { return mReach; }
  std::size_t pairCount() const { return mNeighbours.size() / 2; }
  /// The members b with h(a, b) < reach(), ascending, and those h.
  int degree(int a) const { return int(mOffsets[std::size_t(a) + 1] - mOffsets[std::size_t(a)]); }
  const int* neighbours(int a) const { return mNeighbours.data() + mOffsets[std::size_t(a)]; }
  const double* neighbourDistances(int a) const {
    return mDistances.data() + mOffsets[std::size_t(a)];
  }
  /// h(a, b) of any pair, computed now (streakDistance()).
  double distance(int a, int b) const { return streakDistance(mGroup, a, b); }
  /// The lower bound used to prune pairs (also by orderGreedy() beyond the reach).
  const StreakProjection& projection() const { return *mProjection; }
  /// Figure 4's curve, exact for every h0 <= reach().
  const ThresholdCurve& curve() const { return mCurve; }
  /// Work of the pair search.
  const CandidateStats& stats() const { return mStats; }

 private:
  StreakDistances(StreakGroup group, std::shared_ptr<const StreakProjection> projection,
                  double mean, double reach);
  /// Finds the pairs with h < reach and builds the lists and the curve.
  void build(double reach);

  StreakGroup mGroup;
  std::shared_ptr<const StreakProjection> mProjection;
  double mMean = 0.0;
  double mReach = 0.0;
  std::vector<std::size_t> mOffsets;  ///< size + 1
  std::vector<int> mNeighbours;       ///< both directions of every pair
  std::vector<double> mDistances;
  ThresholdCurve mCurve;
  CandidateStats mStats;
};

}  // namespace plume
