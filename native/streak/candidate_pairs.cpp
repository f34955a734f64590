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

/// Pairs found from one tile of members, and the work it took.
struct TilePairs {
  std::vector<DistancePair> pairs;
  CandidateStats stats;
};

/// Keeps the pairs of a block whose exact h is below reach. The sums run frame by frame over the
/// whole block, so each frame's lines of the block's members are read once for all its pairs
/// (from cache) instead of once per pair (from memory); each pair still adds the same terms in
/// the same order as streakDistanceBelow(), stopping once it reaches reach, so its h is the
/// same bit for bit.
void decideBlock(const StreakGroup& g, const std::vector<std::pair<int, int>>& block, double reach,
                 std::vector<double>& total, TilePairs& out) {
  out.stats.exact += block.size();
  total.assign(block.size(), 0.0);
  for (int f = 0; f < g.usedFrameCount(); ++f) {
    const std::size_t count = 3 * std::size_t(g.particleCount(f));
    const double N = double(g.particleCount(f));
    for (std::size_t k = 0; k < block.size(); ++k) {
      if (total[k] >= reach) continue;  // decided: h >= reach
      const auto [a, b] = block[k];
      total[k] += squaredDifference(g.line(f, a), g.line(f, b), count) / N;
    }
  }
  for (std::size_t k = 0; k < block.size(); ++k)
    if (total[k] < reach) {
      const auto [a, b] = block[k];
      out.pairs.push_back({std::min(a, b), std::max(a, b), total[k]});
    }
}

/// Members of one grid cell taken together, against as many of a neighbouring cell: see
/// decideBlock() (the exact h of many pairs is bound by memory otherwise: every pair streams two
/// streaklines of 3 Σ_t N(t) floats).
constexpr int kTile = 16;

/// Pairs through the grid over projected coordinates 0..2 (fewer if the rank is lower; one cell
/// holding everyone when reach is +inf).
std::vector<TilePairs> gridPairs(const StreakGroup& g, const StreakProjection& q, double reach) {
  const int n = g.size();
  const int dims = std::isinf(reach) ? 0 : std::min(q.rank(), 3);
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
      const double x = (q.coords(a)[j] - lo[std::size_t(j)]) / cell;
      key[std::size_t(a)][std::size_t(j)] = std::int64_t(std::floor(x));
    }
  std::vector<int> order(static_cast<std::size_t>(n));
  for (int a = 0; a < n; ++a) order[std::size_t(a)] = a;
  std::sort(order.begin(), order.end(), [&](int x, int y) {
    const CellKey &kx = key[std::size_t(x)], &ky = key[std::size_t(y)];
    return kx != ky ? kx < ky : x < y;
  });
  // Cells as runs of `order`: cellStart[c] .. cellStart[c + 1].
  std::vector<CellKey> cellKey;
  std::vector<int> cellStart;
  for (int p = 0; p < n; ++p) {
    const CellKey& k = key[std::size_t(order[std::size_t(p)])];
    if (cellKey.empty() || cellKey.back() != k) {
      cellKey.push_back(k);
      cellStart.push_back(p);
    }
  }
  cellStart.push_back(n);

  struct Tile {
    int begin, end, cell;
  };
  std::vector<Tile> tiles;
  for (std::size_t c = 0; c + 1 < cellStart.size(); ++c)
    for (int p = cellStart[c]; p < cellStart[c + 1]; p += kTile)
      tiles.push_back({p, std::min(p + kTile, cellStart[c + 1]), int(c)});

  std::vector<TilePairs> found(tiles.size());
  parallelFor(0, int(tiles.size()), [&](int t) {
    const Tile& tile = tiles[std::size_t(t)];
    TilePairs& out = found[std::size_t(t)];
    std::vector<std::pair<int, int>> block;
    std::vector<double> total;
    // The pairs (p, r), p in the tile, r in [from, to) (p < r within the own cell), that the
    // bound does not rule out, decided together.
    auto visit = [&](int from, int to, bool ownCell) {
      block.clear();
      for (int r = from; r < to; ++r)
        for (int p = tile.begin; p < tile.end; ++p) {
          if (ownCell && p >= r) continue;
          const int a = order[std::size_t(p)], b = order[std::size_t(r)];
          ++out.stats.examined;
          if (q.lowerBound(a, b, limit) >= limit) continue;  // proves h >= reach
          block.emplace_back(a, b);
        }
      decideBlock(g, block, reach, total, out);
    };
    const int cellEnd = cellStart[std::size_t(tile.cell) + 1];
    for (int r = tile.begin; r < cellEnd; r += kTile) visit(r, std::min(r + kTile, cellEnd), true);
    const CellKey& own = cellKey[std::size_t(tile.cell)];
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const CellKey k{own[0] + dx, own[1] + dy, own[2] + dz};
          if (!(own < k)) continue;  // each pair of cells once, from the lower
          const auto it = std::lower_bound(cellKey.begin(), cellKey.end(), k);
          if (it == cellKey.end() || *it != k) continue;
          const std::size_t other = std::size_t(it - cellKey.begin());
          for (int r = cellStart[other]; r < cellStart[other + 1]; r += kTile)
            visit(r, std::min(r + kTile, cellStart[other + 1]), false);
        }
  });
  return found;
}

}  // namespace

CandidatePairs findCandidatePairs(const StreakGroup& g, const StreakProjection& q, double reach) {
  if (std::isnan(reach)) throw std::invalid_argument("reach must be a number (got NaN)");
  if (q.size() != g.size())
    throw std::invalid_argument("projection of " + std::to_string(q.size()) +
                                " members for a group of " + std::to_string(g.size()));
  CandidatePairs result;
  if (!(reach > 0.0) || g.size() < 2) return result;  // h < reach <= 0 never holds
  std::vector<TilePairs> found = gridPairs(g, q, reach);
  std::size_t total = 0;
  for (const TilePairs& m : found) {
    total += m.pairs.size();
    result.stats.examined += m.stats.examined;
    result.stats.exact += m.stats.exact;
  }
  result.pairs.reserve(total);
  for (TilePairs& m : found) {
    result.pairs.insert(result.pairs.end(), m.pairs.begin(), m.pairs.end());
    std::vector<DistancePair>().swap(m.pairs);  // the pairs are held once, not twice
  }
  result.stats.kept = total;
  // Unique keys: one order at any thread count.
  tbb::parallel_sort(result.pairs.begin(), result.pairs.end(),
                     [](const DistancePair& x, const DistancePair& y) {
                       return x.a != y.a ? x.a < y.a : x.b < y.b;
                     });
  return result;
}

}  // namespace plume
