#include "streak/brute_force.h"

#include "core/parallel.h"
#include "streak/disjoint_sets.h"
#include "streak/streak_moments.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace plume {
namespace {

void checkThreshold(double h0) {
  if (!std::isfinite(h0) || h0 < 0.0)
    throw std::invalid_argument("h0 must be a finite number >= 0 (got " + std::to_string(h0) + ")");
}

/// Sets of the members joined by pairs with h < h0.
DisjointSets joinClose(const DistanceMatrix& h, double h0) {
  h.validate();
  checkThreshold(h0);
  DisjointSets sets(h.size);
  for (int a = 0; a < h.size; ++a)
    for (int b = a + 1; b < h.size; ++b)
      if (h(a, b) < h0) sets.join(a, b);
  return sets;
}

}  // namespace

void DistanceMatrix::validate() const {
  if (size < 0 || values.size() != std::size_t(size) * std::size_t(size))
    throw std::invalid_argument("h must be a square matrix (" + std::to_string(values.size()) +
                                " values for size " + std::to_string(size) + ")");
  for (int a = 0; a < size; ++a)
    for (int b = a + 1; b < size; ++b) {
      const double v = (*this)(a, b);
      if (!std::isfinite(v) || v < 0.0)
        throw std::invalid_argument("h must hold finite distances >= 0 (h[" + std::to_string(a) +
                                    ", " + std::to_string(b) + "] = " + std::to_string(v) + ")");
    }
}

DistanceMatrix bruteForceDistances(const StreakGroup& g) {
  const int n = g.size();
  DistanceMatrix h;
  h.size = n;
  h.values.assign(std::size_t(n) * std::size_t(n), 0.0);
  parallelFor(0, n, [&](int a) {
    for (int b = a + 1; b < n; ++b) {
      const double v = streakDistance(g, a, b);
      h.values[std::size_t(a) * std::size_t(n) + std::size_t(b)] = v;
      h.values[std::size_t(b) * std::size_t(n) + std::size_t(a)] = v;
    }
  });
  return h;
}

double bruteForceMean(const DistanceMatrix& h) {
  h.validate();
  if (h.size < 2)
    throw std::invalid_argument(
        "a candidate group needs at least 2 point sources for a default h0 (got " +
        std::to_string(h.size) + ")");
  double sum = 0.0;
  for (int a = 0; a < h.size; ++a)
    for (int b = a + 1; b < h.size; ++b) sum += h(a, b);
  return sum / (0.5 * double(h.size) * double(h.size - 1));
}

std::vector<std::vector<int>> bruteForceClusters(const DistanceMatrix& h, double h0) {
  DisjointSets sets = joinClose(h, h0);
  std::vector<std::vector<int>> byRoot(std::size_t(h.size));
  for (int a = 0; a < h.size; ++a) byRoot[std::size_t(sets.find(a))].push_back(a);
  std::vector<std::vector<int>> clusters;
  for (auto& members : byRoot)
    if (members.size() >= 2) clusters.push_back(std::move(members));
  return clusters;
}

ClusterSummary bruteForceSummary(const DistanceMatrix& h, double h0) {
  DisjointSets sets = joinClose(h, h0);
  ClusterSummary s;
  for (int a = 0; a < h.size; ++a)
    if (sets.find(a) == a && sets.setSize(a) >= 2) {
      ++s.surfaces;
      s.streaklines += sets.setSize(a);
    }
  return s;
}

std::vector<int> bruteForceOrder(const DistanceMatrix& h, const std::vector<int>& members) {
  h.validate();
  std::vector<char> seen(std::size_t(h.size), 0);
  for (int m : members) {
    if (m < 0 || m >= h.size)
      throw std::invalid_argument("member " + std::to_string(m) + " is not in h (size " +
                                  std::to_string(h.size) + ")");
    if (seen[std::size_t(m)])
      throw std::invalid_argument("member " + std::to_string(m) + " repeats");
    seen[std::size_t(m)] = 1;
  }
  const std::size_t n = members.size();
  if (n < 2) return members;
  // The closest pair starts the chain.
  std::size_t bestA = 0, bestB = 1;
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = a + 1; b < n; ++b)
      if (h(members[a], members[b]) < h(members[bestA], members[bestB])) {
        bestA = a;
        bestB = b;
      }
  std::vector<int> chain{members[bestA], members[bestB]};  // front at chain[0]
  std::vector<int> rest;
  for (std::size_t m = 0; m < n; ++m)
    if (m != bestA && m != bestB) rest.push_back(members[m]);
  std::vector<int> front;  // sources attached at the front, in attachment order
  while (!rest.empty()) {
    const int head = front.empty() ? chain.front() : front.back();
    const int tail = chain.back();
    std::size_t pick = 0;
    bool atFront = true;
    double best = INFINITY;
    for (std::size_t r = 0; r < rest.size(); ++r) {
      const double dFront = h(rest[r], head), dBack = h(rest[r], tail);
      if (dFront < best) {
        best = dFront;
        pick = r;
        atFront = true;
      }
      if (dBack < best) {
        best = dBack;
        pick = r;
        atFront = false;
      }
    }
    if (atFront) front.push_back(rest[pick]);
    else chain.push_back(rest[pick]);
    rest.erase(rest.begin() + std::ptrdiff_t(pick));
  }
  std::vector<int> order(front.rbegin(), front.rend());
  order.insert(order.end(), chain.begin(), chain.end());
  return order;
}

std::vector<StreakSurface> bruteForceSurfaces(const std::vector<StreakFrame>& frames,
                                              const std::vector<int>& groups, double h0) {
  if (std::isnan(h0) || std::isinf(h0))
    throw std::invalid_argument("h0 must be a finite number (got " + std::to_string(h0) + ")");
  const SharedStreakFrames shared(SharedStreakFrames(), &frames);
  std::vector<StreakSurface> surfaces;
  for (const auto& [group, ids] : candidateGroups(frames, groups)) {
    const StreakGroup g(shared, ids);
    const DistanceMatrix h = bruteForceDistances(g);
    const double threshold = h0 < 0.0 ? streakMoments(g).meanDistance : h0;
    for (const std::vector<int>& cluster : bruteForceClusters(h, threshold)) {
      StreakSurface s;
      s.group = group;
      s.threshold = threshold;
      for (int m : bruteForceOrder(h, cluster)) s.sources.push_back(ids[std::size_t(m)]);
      surfaces.push_back(std::move(s));
    }
  }
  return surfaces;
}

}  // namespace plume
