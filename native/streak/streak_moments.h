#pragma once
/// \file streak_moments.h
/// The default threshold h0 of §3.3 ([Smoke Surfaces]), "the average value of h", without
/// visiting the pairs: Σ_{α<β} |p_α − p_β|² = n Σ_α |p_α − m|² for every (t, i), with m the mean
/// of the group's particles (t, i). O(n · particles · frames) instead of O(n² · ...).

#include "streak/streak_group.h"

#include <vector>

namespace plume {

/// §3.3: first and second moments of a group's streaklines, which give the default h0.
struct StreakMoments {
  /// m(t,i) = (1/n) Σ_α p(α,t,i): D = 3 Σ_t N(t) values, used frames in order, x y z per particle.
  std::vector<double> meanLine;
  /// Σ_{α<β} h(α,β) = Σ_t (n / N(t)) Σ_i Σ_α |p(α,t,i) − m(t,i)|² (centred, so no cancellation).
  double pairSum = 0.0;
  /// §3.3 default h0: pairSum / (n(n−1)/2), the mean of h over the pairs α < β; 0 when n < 2.
  double meanDistance = 0.0;
};

/// §3.3: the moments above, in double. Frames are summed in parallel, each in a fixed order, and
/// the frame totals in frame order, so the result does not depend on the thread count.
StreakMoments streakMoments(const StreakGroup& g);

}  // namespace plume
