#pragma once
/// \file streak_projection.h
/// A cheap lower bound of §3.3's h(α,β) ([Smoke Surfaces]) to prune pairs. h is a squared
/// Euclidean distance, h(α,β) = |x_α − x_β|², where x_α lists p(α,t,i)/√N(t) over every used
/// frame t and particle i (D = 3 Σ_t N(t) coordinates). For orthonormal directions V,
/// |Vᵀ(x_α − x_β)|² <= h(α,β) (Bessel). V holds the leading principal directions of the group
/// (PCA of an evenly spaced sample), which carry most of h: on the 10,752 streaklines of a 40³
/// plume, 8 (16) directions give a median bound of 0.47 h (0.62 h) for the closest 0.1 % of
/// pairs, where the per-frame centroids (the Jensen bound T_t >= |c_α(t) − c_β(t)|²) give
/// 0.12 h; rank costs n·D each, exact h D per pair surviving the bound.

#include "streak/streak_group.h"

#include <vector>

namespace plume {

/// §3.3 pruning of the pairs: how the directions of the lower bound on h are found.
struct ProjectionParams {
  int rank = 8;          ///< principal directions kept (0: none; every pair is then checked)
  int sampleSize = 128;  ///< evenly spaced members whose PCA gives the directions
  int iterations = 24;   ///< subspace iterations on the sample's Gram matrix
  /// Groups of fewer members get no directions (every pair is then checked, stopping early
  /// above the reach): finding directions costs more than the n²/2 pairs of a small group.
  int minSize = 512;
  /// Throws std::invalid_argument unless rank in [0, 64], sampleSize in [2, 4096], iterations
  /// in [1, 1000] and minSize >= 0.
  void validate() const;
};

/// §3.3 lower bound on h: coordinates q_α = Vᵀ(x_α − m) of every member of a group on orthonormal
/// directions V; the bound |q_α − q_β|² <= h(α,β) holds for any V with orthonormal columns and any
/// m, so the quality of the PCA only affects speed, never results.
class StreakProjection {
 public:
  StreakProjection() = default;
  StreakProjection(int size, int rank, std::vector<double> coords, double margin);

  int size() const { return mSize; }
  int rank() const { return mRank; }
  const double* coords(int a) const { return mCoords.data() + std::size_t(a) * std::size_t(mRank); }

  /// |q_a − q_b|², summed over the directions in order. Stops once the running sum reaches
  /// `limit` and returns it (the first k terms alone are a lower bound too; rounding is monotonic).
  double lowerBound(int a, int b, double limit) const;

  /// Rounding allowance: a computed bound L >= x + slack(x) proves that the computed h of the
  /// pair is >= x (slack covers the rounding of q, of L and of h, relative 1e-9 plus an
  /// absolute term from the largest |x_α − m|², far above the worst case).
  double slack(double x) const { return 1e-9 * x + mMargin; }

 private:
  int mSize = 0;
  int mRank = 0;
  std::vector<double> mCoords;  ///< size × rank
  double mMargin = 0.0;
};

/// §3.3 pruning directions of a group and the coordinates of its members; meanLine is m (e.g.
/// StreakMoments::meanLine: D values). Deterministic (fixed sample, seeded start, sums in
/// fixed order): the same at any thread count.
StreakProjection projectStreaks(const StreakGroup& g, const std::vector<double>& meanLine,
                                const ProjectionParams& params);

}  // namespace plume
