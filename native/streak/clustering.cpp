#include "streak/clustering.h"

#include "core/parallel.h"
#include "streak/disjoint_sets.h"

#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

namespace plume {
namespace {

/// h0 must be a number >= 0 within the reach of the held pairs.
void checkThreshold(const StreakDistances& h, double h0) {
  if (!std::isfinite(h0) || h0 < 0.0)
    throw std::invalid_argument("h0 must be a finite number >= 0 (got " + std::to_string(h0) + ")");
  if (h0 > h.reach())
    throw std::invalid_argument("h0 = " + std::to_string(h0) + " is above the reach " +
                                std::to_string(h.reach()) +
                                " of these distances (only pairs with h below it are held); "
                                "compute them with a reach >= h0");
}

}  // namespace

double defaultThreshold(const StreakDistances& h) { return h.meanDistance(); }

std::vector<std::vector<int>> clusterSources(const StreakDistances& h, double h0) {
  checkThreshold(h, h0);
  const int n = h.size();
  DisjointSets sets(n);
  for (int a = 0; a < n; ++a)
    for (int i = 0; i < h.degree(a); ++i)
      if (h.neighbours(a)[i] > a && h.neighbourDistances(a)[i] < h0)
        sets.join(a, h.neighbours(a)[i]);
  std::vector<std::vector<int>> byRoot(static_cast<std::size_t>(n));
  for (int a = 0; a < n; ++a) byRoot[std::size_t(sets.find(a))].push_back(a);
  // Roots are the smallest members, so walking roots in order sorts clusters by first member.
  std::vector<std::vector<int>> clusters;
  for (auto& members : byRoot)
    if (members.size() >= 2) clusters.push_back(std::move(members));
  return clusters;
}

ClusterSummary clusterSummary(const StreakDistances& h, double h0) {
  checkThreshold(h, h0);
  return h.curve().at(h0);
}

std::vector<std::pair<int, std::vector<int>>> candidateGroups(
    const std::vector<StreakFrame>& frames, const std::vector<int>& groups) {
  if (frames.empty()) throw std::invalid_argument("no streak frames: bake the streaklines first");
  const std::vector<int>& g = groups.empty() ? frames.back().groups : groups;
  if (int(g.size()) != frames.back().sourceCount())
    throw std::invalid_argument(std::to_string(g.size()) + " candidate groups given for " +
                                std::to_string(frames.back().sourceCount()) + " point sources");
  std::map<int, std::vector<int>> members;  // ordered by group number
  for (std::size_t s = 0; s < g.size(); ++s) members[g[s]].push_back(int(s));
  for (const auto& [group, ids] : members)
    if (ids.size() < 2)
      throw std::invalid_argument("candidate group " + std::to_string(group) +
                                  " has a single point source; a surface needs at least 2 "
                                  "streaklines");
  return {members.begin(), members.end()};
}

std::vector<StreakSurface> buildSurfaces(const std::vector<StreakFrame>& frames,
                                         const std::vector<int>& groups, double h0,
                                         const ProjectionParams& projection) {
  if (std::isnan(h0) || std::isinf(h0))
    throw std::invalid_argument("h0 must be a finite number (got " + std::to_string(h0) + ")");
  // The frames outlive every object built here: a non-owning shared pointer.
  const SharedStreakFrames shared(SharedStreakFrames(), &frames);
  std::vector<StreakSurface> surfaces;
  for (const auto& [group, ids] : candidateGroups(frames, groups)) {
    DistanceParams params;
    params.reach = h0 < 0.0 ? -1.0 : h0;  // the pairs that decide the clusters, no more
    params.projection = projection;
    const StreakDistances h(StreakGroup(shared, ids), params);
    const double threshold = h0 < 0.0 ? h.meanDistance() : h0;
    const std::vector<std::vector<int>> clusters = clusterSources(h, threshold);
    std::vector<std::vector<int>> orders(clusters.size());
    parallelFor(0, int(clusters.size()),
                [&](int c) { orders[std::size_t(c)] = orderGreedy(h, clusters[std::size_t(c)]); });
    for (const std::vector<int>& order : orders) {
      StreakSurface s;
      s.group = group;
      s.threshold = threshold;
      for (int m : order) s.sources.push_back(ids[std::size_t(m)]);
      surfaces.push_back(std::move(s));
    }
  }
  return surfaces;
}

}  // namespace plume
