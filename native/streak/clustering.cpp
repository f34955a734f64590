#include "streak/clustering.h"

#include "core/parallel.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

namespace plume {
namespace {

/// Union-find whose roots are always the smallest index of their set (deterministic output).
class DisjointSets {
 public:
  explicit DisjointSets(int n) : mParent(std::size_t(n)) { std::iota(mParent.begin(), mParent.end(), 0); }
  int find(int a) {
    while (mParent[std::size_t(a)] != a) {
      mParent[std::size_t(a)] = mParent[std::size_t(mParent[std::size_t(a)])];  // path halving
      a = mParent[std::size_t(a)];
    }
    return a;
  }
  void join(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (b < a) std::swap(a, b);
    mParent[std::size_t(b)] = a;
  }

 private:
  std::vector<int> mParent;
};

void checkThreshold(double h0) {
  if (!std::isfinite(h0) || h0 < 0.0)
    throw std::invalid_argument("h0 must be a finite number >= 0 (got " + std::to_string(h0) + ")");
}

/// Sets of the sources joined by pairs with h < h0.
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

DistanceMatrix streakDistances(const std::vector<StreakFrame>& frames,
                               const std::vector<int>& sourceIds) {
  const int n = int(sourceIds.size());
  // Per frame: N(t) and the offset of each group member's first particle.
  std::vector<std::size_t> count(frames.size(), 0);
  std::vector<std::vector<std::size_t>> start(frames.size());
  for (std::size_t t = 0; t < frames.size(); ++t) {
    const StreakFrame& f = frames[t];
    f.validate();
    const std::vector<std::size_t> offsets = f.offsets();
    start[t].resize(std::size_t(n));
    for (int a = 0; a < n; ++a) {
      const int id = sourceIds[std::size_t(a)];
      if (id < 0 || id >= f.sourceCount())
        throw std::invalid_argument("source ID " + std::to_string(id) + " is not in frame " +
                                    std::to_string(t) + " (" + std::to_string(f.sourceCount()) +
                                    " sources)");
      const std::size_t c = std::size_t(f.counts[std::size_t(id)]);
      if (a == 0) count[t] = c;
      else if (c != count[t])
        throw std::invalid_argument("sources " + std::to_string(sourceIds[0]) + " and " +
                                    std::to_string(id) + " hold " + std::to_string(count[t]) +
                                    " and " + std::to_string(c) + " particles on frame " +
                                    std::to_string(t) + "; h needs equal counts N(t)");
      start[t][std::size_t(a)] = offsets[std::size_t(id)];
    }
  }
  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(std::size_t(n) * std::size_t(std::max(n - 1, 0)) / 2);
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b) pairs.emplace_back(a, b);

  DistanceMatrix h;
  h.size = n;
  h.values.assign(std::size_t(n) * std::size_t(n), 0.0);
  parallelFor(0, int(pairs.size()), [&](int p) {
    const int a = pairs[std::size_t(p)].first, b = pairs[std::size_t(p)].second;
    double total = 0.0;
    for (std::size_t t = 0; t < frames.size(); ++t) {
      const std::size_t N = count[t];
      if (N == 0) continue;  // nothing emitted yet: the term is undefined, not zero
      const glm::vec3* pa = frames[t].positions.data() + start[t][std::size_t(a)];
      const glm::vec3* pb = frames[t].positions.data() + start[t][std::size_t(b)];
      double sum = 0.0;
      for (std::size_t i = 0; i < N; ++i) {
        const double dx = double(pa[i].x) - double(pb[i].x);
        const double dy = double(pa[i].y) - double(pb[i].y);
        const double dz = double(pa[i].z) - double(pb[i].z);
        sum += dx * dx + dy * dy + dz * dz;
      }
      total += sum / double(N);
    }
    h.values[std::size_t(a) * std::size_t(n) + std::size_t(b)] = total;
    h.values[std::size_t(b) * std::size_t(n) + std::size_t(a)] = total;
  });
  return h;
}

double defaultThreshold(const DistanceMatrix& h) {
  h.validate();
  if (h.size < 2)
    throw std::invalid_argument("a candidate group needs at least 2 point sources for a default h0 (got " +
                                std::to_string(h.size) + ")");
  double sum = 0.0;
  for (int a = 0; a < h.size; ++a)
    for (int b = a + 1; b < h.size; ++b) sum += h(a, b);
  return sum / (0.5 * double(h.size) * double(h.size - 1));
}

std::vector<std::vector<int>> clusterSources(const DistanceMatrix& h, double h0) {
  DisjointSets sets = joinClose(h, h0);
  std::vector<std::vector<int>> byRoot(std::size_t(h.size));
  for (int a = 0; a < h.size; ++a) byRoot[std::size_t(sets.find(a))].push_back(a);
  // Roots are the smallest members, so walking roots in order sorts clusters by first member.
  std::vector<std::vector<int>> clusters;
  for (auto& members : byRoot)
    if (members.size() >= 2) clusters.push_back(std::move(members));
  return clusters;
}

ClusterSummary clusterSummary(const DistanceMatrix& h, double h0) {
  DisjointSets sets = joinClose(h, h0);
  std::vector<int> size(std::size_t(h.size), 0);
  for (int a = 0; a < h.size; ++a) ++size[std::size_t(sets.find(a))];
  ClusterSummary s;
  for (int c : size)
    if (c >= 2) {
      ++s.surfaces;
      s.streaklines += c;
    }
  return s;
}

std::vector<int> orderGreedy(const DistanceMatrix& h, const std::vector<int>& members) {
  h.validate();
  std::vector<char> seen(std::size_t(h.size), 0);
  for (int m : members) {
    if (m < 0 || m >= h.size)
      throw std::invalid_argument("member " + std::to_string(m) + " is not in h (size " +
                                  std::to_string(h.size) + ")");
    if (seen[std::size_t(m)]) throw std::invalid_argument("member " + std::to_string(m) + " repeats");
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

std::vector<StreakSurface> buildSurfaces(const std::vector<StreakFrame>& frames,
                                         const std::vector<int>& groups, double h0) {
  if (frames.empty()) throw std::invalid_argument("no streak frames: bake the streaklines first");
  const std::vector<int>& g = groups.empty() ? frames.back().groups : groups;
  if (int(g.size()) != frames.back().sourceCount())
    throw std::invalid_argument(std::to_string(g.size()) + " candidate groups given for " +
                                std::to_string(frames.back().sourceCount()) + " point sources");
  if (std::isnan(h0) || std::isinf(h0))
    throw std::invalid_argument("h0 must be a finite number (got " + std::to_string(h0) + ")");
  std::map<int, std::vector<int>> members;  // ordered by group number
  for (std::size_t s = 0; s < g.size(); ++s) members[g[s]].push_back(int(s));
  std::vector<StreakSurface> surfaces;
  for (const auto& [group, ids] : members) {
    if (ids.size() < 2)
      throw std::invalid_argument("candidate group " + std::to_string(group) +
                                  " has a single point source; a surface needs at least 2 "
                                  "streaklines");
    const DistanceMatrix h = streakDistances(frames, ids);
    const double threshold = h0 < 0.0 ? defaultThreshold(h) : h0;
    for (const std::vector<int>& cluster : clusterSources(h, threshold)) {
      StreakSurface s;
      s.group = group;
      s.threshold = threshold;
      for (int m : orderGreedy(h, cluster)) s.sources.push_back(ids[std::size_t(m)]);
      surfaces.push_back(std::move(s));
    }
  }
  return surfaces;
}

}  // namespace plume
