#include "streak/candidate_pairs.h"

#include "core/parallel.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

using CellKey = std::array<std::int64_t, 3>;

/// Pairs found from one member, and the work it took.
struct MemberPairs {
  std::vector<DistancePair> pairs;
  CandidateStats stats;
};

/// Keeps (a, b) if its exact h is below reach.
void decide(const StreakGroup& g, int a, int b, double reach, MemberPairs& out) {
  ++out.stats.exact;
  const double h = streakDistanceBelow(g, a, b, reach);
  if (h < reach) out.pairs.push_back({std::min(a, b), std::max(a, b), h});
}

/// Every pair, exactly (reach = +inf).
std::vector<MemberPairs> allPairs(const StreakGroup& g) {
  const int n = g.size();
  std::vector<MemberPairs> found(static_cast<std::size_t>(n));
  parallelFor(0, n, [&](int a) {
    MemberPairs& out = found[std::size_t(a)];
    for (int b = a + 1; b < n; ++b) {
      ++out.stats.examined;
      decide(g, a, b, std::numeric_limits<double>::infinity(), out);
    }
  });
  return found;
}

/// Pairs through the grid over projected coordinates 0..2 (fewer if the rank is lower).
std::vector<MemberPairs> gridPairs(const StreakGroup& g, const StreakProjection& q, double reach) {
  const int n = g.size();
  const int dims = std::min(q.rank(), 3);
  const double limit = reach + q.slack(reach);
  const double cell = std::sqrt(limit) * (1.0 + 1e-6);  // rounding of the cell index
  std::array<double, 3> lo{0.0, 0.0, 0.0};
  for (int j = 0; j < dims; ++j) {
    lo[std::size_t(j)] = std::numeric_limits<double>::infinity();
    for (int a = 0; a < n; ++a) lo[std::size_t(j)] = std::min(lo[std::size_t(j)], q.coords(a)[j]);
  }
  std::vector<CellKey> key(std::size_t(n), CellKey{0, 0, 0});
  for (int a = 0; a < n; ++a)
    for (int j = 0; j < dims; ++j) {
      // The coordinate range is <= 2 max|y| and the cell >= √margin ∝ max|y|: no overflow.
      key[std::size_t(a)][std::size_t(j)] = std::int64_t(std::floor((q.coords(a)[j] - lo[std::size_t(j)]) / cell));
    }
  std::vector<int> order(static_cast<std::size_t>(n));
  for (int a = 0; a < n; ++a) order[std::size_t(a)] = a;
  std::sort(order.begin(), order.end(), [&](int x, int y) {
    return key[std::size_t(x)] != key[std::size_t(y)] ? key[std::size_t(x)] < key[std::size_t(y)] : x < y;
  });
  // Cells as runs of `order`: cellStart[c] .. cellStart[c + 1].
  std::vector<CellKey> cellKey;
  std::vector<int> cellStart, cellOf(static_cast<std::size_t>(n));
  for (int p = 0; p < n; ++p) {
    const CellKey& k = key[std::size_t(order[std::size_t(p)])];
    if (cellKey.empty() || cellKey.back() != k) {
      cellKey.push_back(k);
      cellStart.push_back(p);
    }
    cellOf[std::size_t(p)] = int(cellKey.size()) - 1;
  }
  cellStart.push_back(n);

  std::vector<MemberPairs> found(static_cast<std::size_t>(n));
  parallelFor(0, n, [&](int p) {
    const int a = order[std::size_t(p)];
    const int c = cellOf[std::size_t(p)];
    MemberPairs& out = found[std::size_t(p)];
    auto visit = [&](int from, int to) {
      for (int r = from; r < to; ++r) {
        const int b = order[std::size_t(r)];
        ++out.stats.examined;
        if (q.lowerBound(a, b, limit) >= limit) continue;  // proves h >= reach
        decide(g, a, b, reach, out);
      }
    };
    visit(p + 1, cellStart[std::size_t(c) + 1]);  // own cell: later members only
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const CellKey k{cellKey[std::size_t(c)][0] + dx, cellKey[std::size_t(c)][1] + dy,
                          cellKey[std::size_t(c)][2] + dz};
          if (!(cellKey[std::size_t(c)] < k)) continue;  // each pair of cells once, from the lower
          const auto it = std::lower_bound(cellKey.begin(), cellKey.end(), k);
          if (it == cellKey.end() || *it != k) continue;
          const std::size_t other = std::size_t(it - cellKey.begin());
          visit(cellStart[other], cellStart[other + 1]);
        }
  });
  return found;
}

}  // namespace

CandidatePairs findCandidatePairs(const StreakGroup& g, const StreakProjection& q, double reach) {
  if (std::isnan(reach)) throw std::invalid_argument("reach must be a number (got NaN)");
  if (q.size() != g.size())
    throw std::invalid_argument("projection of " + std::to_string(q.size()) + " members for a group of " +
                                std::to_string(g.size()));
  CandidatePairs result;
  if (!(reach > 0.0) || g.size() < 2) return result;  // h < reach <= 0 never holds
  std::vector<MemberPairs> found = std::isinf(reach) ? allPairs(g) : gridPairs(g, q, reach);
  std::size_t total = 0;
  for (const MemberPairs& m : found) {
    total += m.pairs.size();
    result.stats.examined += m.stats.examined;
    result.stats.exact += m.stats.exact;
  }
  result.pairs.reserve(total);
  for (MemberPairs& m : found) {
    result.pairs.insert(result.pairs.end(), m.pairs.begin(), m.pairs.end());
    std::vector<DistancePair>().swap(m.pairs);  // the pairs are held once, not twice
  }
  result.stats.kept = total;
  tbb::parallel_sort(result.pairs.begin(), result.pairs.end(), [](const DistancePair& x, const DistancePair& y) {
    return x.a != y.a ? x.a < y.a : x.b < y.b;  // unique keys: one order at any thread count
  });
  return result;
}

}  // namespace plume
