#pragma once
/// \file streak_group.h
/// The streaklines of one candidate group as the distance of §3.3 ([Smoke Surfaces]) sees
/// them: p(α,t,i) read in place from frames shared by every group of a shot, and h(α,β) itself,
/// computed one way only so that every clustering path agrees bit for bit.

#include "tracers/streak_frame.h"

#include <cstddef>
#include <memory>
#include <vector>

namespace plume {

/// §3.2 streak frames of one shot, shared by its groups and by the distance objects built on them
/// (only counts and positions are read). A non-owning pointer (aliasing constructor) does for
/// callers that keep the frames alive themselves.
using SharedStreakFrames = std::shared_ptr<const std::vector<StreakFrame>>;

/// §3.3: the positions p(α,t,i) of a candidate group's point sources. Member a (0..size-1) is
/// source sourceIds[a]; "used frames" are the frames with N(t) > 0 (h skips the others).
class StreakGroup {
 public:
  /// Throws std::invalid_argument on an ID out of range, counts and positions that disagree, or
  /// members holding different particle counts on one frame (h needs equal N(t)).
  StreakGroup(SharedStreakFrames frames, std::vector<int> sourceIds);

  int size() const { return int(mSourceIds.size()); }
  const std::vector<int>& sourceIds() const { return mSourceIds; }
  const SharedStreakFrames& frames() const { return mFrames; }
  /// Frames with N(t) > 0.
  int usedFrameCount() const { return int(mCounts.size()); }
  /// N(t) of used frame f.
  int particleCount(int f) const { return mCounts[std::size_t(f)]; }
  /// 3·N(t) floats of member a on used frame f: x, y, z of each particle, oldest first.
  const float* line(int f, int a) const {
    return mLines[std::size_t(f) * mSourceIds.size() + std::size_t(a)];
  }
  /// Coordinates of one streakline over the used frames, D = 3 Σ_t N(t).
  std::size_t coordinateCount() const { return mCoordinates; }

 private:
  SharedStreakFrames mFrames;
  std::vector<int> mSourceIds;
  std::vector<int> mCounts;           ///< N(t) per used frame
  std::vector<const float*> mLines;   ///< [f * size + a]
  std::size_t mCoordinates = 0;
};

/// §3.3 inner sum of h: Σ_k (a_k − b_k)² over `count` floats, in double, element k added to partial
/// sum k mod 8, the partial sums added pairwise, ((s0 + s1) + (s2 + s3)) + ((s4 + s5) + (s6 + s7)):
/// the one summation order of h.
double squaredDifference(const float* a, const float* b, std::size_t count);

/// §3.3: h(α,β) = Σ_t [Σ_{i=1}^{N(t)} |p(α,t,i) − p(β,t,i)|²] / N(t) for members a and b, over
/// the used frames in order: total += squaredDifference(...) / N(t). Every path (sparse, on
/// demand, brute force) adds these terms in this order (this function, streakDistanceBelow() or
/// the blocked sums of findCandidatePairs()), so equal inputs give bit-identical h.
double streakDistance(const StreakGroup& g, int a, int b);

/// §3.3 h(α,β) decided against a limit: streakDistance(g, a, b) when that is below `limit`.
/// Otherwise it may stop after the first frame whose running sum reaches `limit` and return that
/// partial sum, which is then <= h and >= limit (the terms are >= 0, and rounding is monotonic), so
/// "result < limit" decides "h < limit" exactly.
double streakDistanceBelow(const StreakGroup& g, int a, int b, double limit);

}  // namespace plume
