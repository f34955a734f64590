#pragma once
/// \file clustering.h
/// Surface reconstruction from streaklines (smoke_surfaces.txt §3.3): the distance h(α,β)
/// between the streaklines of two point sources, clustering of a candidate group with the
/// threshold h0 (default: mean of the h values), and the greedy minimum-length ordering of the
/// streaklines of each surface (Figure 5).

#include "tracers/streak_frame.h"

#include <vector>

namespace plume {

/// Symmetric matrix of the distances h between the sources of one candidate group (indices are
/// positions in the group, 0..size-1). The functions below read only the upper triangle.
struct DistanceMatrix {
  int size = 0;
  std::vector<double> values;  ///< row-major, size × size, zero diagonal

  /// h(a, b) for a != b, read from the upper triangle.
  double operator()(int a, int b) const {
    return a < b ? values[std::size_t(a) * std::size_t(size) + std::size_t(b)]
                 : values[std::size_t(b) * std::size_t(size) + std::size_t(a)];
  }
  /// Throws std::invalid_argument unless values has size² entries, all finite and >= 0.
  void validate() const;
};

/// §3.3: h(α,β) = Σ_t [Σ_{i=1}^{N(t)} |p(α,t,i) − p(β,t,i)|²] / N(t), summed over the stored
/// frames t, with N(t) the particles of each source at t (frames with N(t) = 0 are skipped).
/// `sourceIds` are the sources of the group (IDs = indices into each frame's counts); result
/// entry (a, b) is h(sourceIds[a], sourceIds[b]). Pairs are computed in parallel, each as a
/// sequential double sum, so the result does not depend on the thread count. Throws
/// std::invalid_argument on an ID out of range, an inconsistent frame, or sources of the group
/// holding different particle counts on one frame.
DistanceMatrix streakDistances(const std::vector<StreakFrame>& frames,
                               const std::vector<int>& sourceIds);

/// §3.3: the default threshold h0, the mean of h over the group's pairs α < β. Throws
/// std::invalid_argument for fewer than 2 sources.
double defaultThreshold(const DistanceMatrix& h);

/// §3.3: sources with h(α,β) < h0 share a surface, transitively (union-find over the pairs).
/// Returns the clusters of at least 2 sources (a surface needs 2 streaklines; singletons take no
/// part), each sorted ascending, clusters ordered by their first member. h0 must be finite and
/// >= 0 (std::invalid_argument); h0 = 0 joins nothing.
std::vector<std::vector<int>> clusterSources(const DistanceMatrix& h, double h0);

/// Number of surfaces and of the streaklines they use for a threshold h0 (Figure 4), without
/// building the clusters' lists; O(size²), meant for live UI updates.
struct ClusterSummary {
  int surfaces = 0;
  int streaklines = 0;
};
ClusterSummary clusterSummary(const DistanceMatrix& h, double h0);

/// §3.3 (Figure 5): greedy minimum-length ordering of a surface's streaklines. Starts from the
/// pair (α, β) with the smallest h among `members`, then repeatedly adds the source γ minimising
/// h(γ, end) over both ends of the chain and attaches it at that end. Ties go to the earlier
/// member (in the order given) and to the front end. Returns `members` reordered. Throws
/// std::invalid_argument on an index out of range or a repeated member.
std::vector<int> orderGreedy(const DistanceMatrix& h, const std::vector<int>& members);

/// One streak surface: its candidate group and its streaklines' source IDs, ordered across the
/// surface (the v direction of the NURBS, §3.3 Figure 6).
struct StreakSurface {
  int group = 0;
  double threshold = 0.0;   ///< h0 used for the group
  std::vector<int> sources;
};

/// §3.3 end to end: for each candidate group (ascending group number) the distances, the
/// threshold (`h0` if >= 0, else the group's default), the clusters and their greedy order.
/// `groups` holds the candidate group of every source (empty: the last frame's groups).
/// Throws std::invalid_argument when a group has a single point source, or on bad frames.
std::vector<StreakSurface> buildSurfaces(const std::vector<StreakFrame>& frames,
                                         const std::vector<int>& groups, double h0);

}  // namespace plume
