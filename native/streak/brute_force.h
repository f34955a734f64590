#pragma once
/// \file brute_force.h
/// The reference of §3.3 ([Smoke Surfaces]) over all pairs: the dense n × n matrix of h, the
/// mean, union-find over every pair, and the greedy order reading the matrix. O(n²) memory, so
/// only for tests and benchmarks: the sparse path (clustering.h) must reproduce it exactly.

#include "streak/clustering.h"
#include "streak/streak_group.h"

#include <vector>

namespace plume {

/// Symmetric matrix of the distances h between the members of one group (zero diagonal). The
/// functions below read only the upper triangle.
struct DistanceMatrix {
  int size = 0;
  std::vector<double> values;  ///< row-major, size × size

  /// h(a, b) for a != b, read from the upper triangle.
  double operator()(int a, int b) const {
    return a < b ? values[std::size_t(a) * std::size_t(size) + std::size_t(b)]
                 : values[std::size_t(b) * std::size_t(size) + std::size_t(a)];
  }
  /// Throws std::invalid_argument unless values has size² entries, all finite and >= 0.
  void validate() const;
};

/// §3.3: h for every pair of members, each from streakDistance() (so bit-identical to the sparse
/// path), pairs in parallel.
DistanceMatrix bruteForceDistances(const StreakGroup& g);

/// §3.3: the mean of h over the pairs α < β, summed pair by pair. Throws std::invalid_argument
/// for fewer than 2 members.
double bruteForceMean(const DistanceMatrix& h);

/// §3.3: clusters of the relation h < h0 over every pair (union-find), as clusterSources().
std::vector<std::vector<int>> bruteForceClusters(const DistanceMatrix& h, double h0);

/// Figure 4 counts for h0 over every pair, as clusterSummary().
ClusterSummary bruteForceSummary(const DistanceMatrix& h, double h0);

/// §3.3 (Figure 5): the greedy order of orderGreedy(), scanning the whole matrix at each step.
std::vector<int> bruteForceOrder(const DistanceMatrix& h, const std::vector<int>& members);

/// buildSurfaces() over dense matrices. The default h0 is the same as buildSurfaces' (the
/// centred mean of streakMoments()), so that the two differ only in how they find pairs.
std::vector<StreakSurface> bruteForceSurfaces(const std::vector<StreakFrame>& frames,
                                              const std::vector<int>& groups, double h0);

}  // namespace plume
