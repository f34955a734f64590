#pragma once
/// \file clustering.h
/// Surface reconstruction from streaklines ([Smoke Surfaces] §3.3): clustering of a candidate
/// group with the threshold h0 (default: the mean of h), the counts of Figure 4, and the whole
/// path from frames to ordered surfaces. Works on sparse distances (StreakDistances): exact for
/// every h0 up to their reach, never an n × n matrix.

#include "streak/greedy_order.h"
#include "streak/streak_distances.h"
#include "tracers/streak_frame.h"

#include <vector>

namespace plume {

/// §3.3: the default threshold h0, the mean of h over the group's pairs α < β. Throws
/// std::invalid_argument for fewer than 2 sources.
double defaultThreshold(const StreakDistances& h);

/// §3.3: sources with h(α,β) < h0 share a surface, transitively (union-find over the held
/// pairs). Returns the clusters of at least 2 sources (a surface needs 2 streaklines; singletons
/// take no part), each sorted ascending, clusters ordered by their first member. Exact, i.e. the
/// brute-force clusters, for 0 <= h0 <= h.reach(); throws std::invalid_argument for h0 < 0, not
/// finite, or above the reach (the pairs that would decide are not held).
std::vector<std::vector<int>> clusterSources(const StreakDistances& h, double h0);

/// Number of surfaces and streaklines for threshold h0 (Figure 4), from h.curve() in
/// O(log pairs): meant for live UI updates. Same range and errors as clusterSources().
ClusterSummary clusterSummary(const StreakDistances& h, double h0);

/// One streak surface: its candidate group and its streaklines' source IDs, ordered across the
/// surface (the v direction of the NURBS, §3.3 Figure 6).
struct StreakSurface {
  int group = 0;
  double threshold = 0.0;   ///< h0 used for the group
  std::vector<int> sources;
};

/// §3.3 end to end: for each candidate group (ascending group number) the sparse distances up to
/// the threshold (`h0` if >= 0, else the group's default), the clusters and their greedy order
/// (clusters ordered in parallel, each on its own: the result does not depend on the thread
/// count). `groups` holds the candidate group of every source (empty: the last frame's groups).
/// Throws std::invalid_argument when a group has a single point source, or on bad frames.
std::vector<StreakSurface> buildSurfaces(const std::vector<StreakFrame>& frames,
                                         const std::vector<int>& groups, double h0,
                                         const ProjectionParams& projection = {});

/// The sources of each candidate group, ascending group number (`groups` as in buildSurfaces()).
/// Throws std::invalid_argument on a group with a single point source, or on a size mismatch.
std::vector<std::pair<int, std::vector<int>>> candidateGroups(
    const std::vector<StreakFrame>& frames, const std::vector<int>& groups);

}  // namespace plume
