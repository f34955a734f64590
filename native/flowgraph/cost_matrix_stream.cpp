/// \file cost_matrix_stream.cpp
/// C of eq. 9-10 (§4.3) with the groups streamed from the pathline files, row block × column
/// block. Row block I (R nodes) is read once; its own pairs are computed, then every column
/// block after it is read and paired with it, kCostTile × kCostTile tiles in parallel. The
/// tiles are those of the in-memory build (R and the column block are multiples of kCostTile,
/// blocks start on tile boundaries), computed by the same kernel: the same bits, the same
/// progress count.

#include "flowgraph/cost_matrix_stream.h"

#include "core/parallel.h"
#include "flowgraph/cost_tiles.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace plume {
namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::vector<GroupArrays> arraysOf(const std::vector<PathlineGroup>& groups) {
  std::vector<GroupArrays> a;
  for (const PathlineGroup& g : groups) a.push_back(groupArrays(g));
  return a;
}

}  // namespace

CostMatrix computeCostMatrix(const NodeFiles& nodes, const FlowGraphParams& params, CostMatrixProgress* progress,
                             const CostStreamParams& stream, CostStreamStats* stats) {
  params.validate();
  if (stream.columnNodes < 1 || stream.columnNodes > (1 << 20))
    throw std::invalid_argument("column_nodes must be in [1, 1048576] (got " + std::to_string(stream.columnNodes) +
                                ")");
  const Clock::time_point start = Clock::now();
  const int n = nodes.size();
  const PathlineLayout layout = nodes.layout();
  const std::size_t tileBytes = nodes.groupBytes() * std::size_t(kCostTile);
  const int rowNodes = int(std::min<std::size_t>(std::max<std::size_t>(1, stream.rowBlockBytes / tileBytes),
                                                 std::size_t(n / kCostTile + 1))) * kCostTile;
  const int columnNodes = (stream.columnNodes + kCostTile - 1) / kCostTile * kCostTile;
  CostStreamStats s;
  s.rowNodes = rowNodes;
  s.columnNodes = columnNodes;

  CostMatrix cost(n);
  ThreadLimit limit(params.threads);
  if (progress) progress->tiles = costTileCount(n);
  auto cancelled = [&] { return progress && progress->cancel.load(std::memory_order_relaxed); };
  auto read = [&](int first, std::vector<PathlineGroup>& groups, int count) {
    const Clock::time_point t0 = Clock::now();
    groups.resize(std::size_t(count));
    nodes.read(first, groups);
    s.groupReads += count;
    s.readSeconds += since(t0);
  };
  // Tiles (row tile a of the row block) × (column tile b of `cols`), as one parallel loop.
  auto pairTiles = [&](const std::vector<GroupArrays>& rows, int r0,
                       const std::vector<std::pair<int, int>>& tiles, const std::vector<GroupArrays>& cols, int c0) {
    parallelFor(0, int(tiles.size()), [&](int t) {
      if (cancelled()) return;
      const int a = tiles[std::size_t(t)].first * kCostTile, b = tiles[std::size_t(t)].second * kCostTile;
      costTile(&rows[std::size_t(a)], r0 + a, std::min(kCostTile, int(rows.size()) - a), &cols[std::size_t(b)],
               c0 + b, std::min(kCostTile, int(cols.size()) - b), layout, params, cost);
      if (progress) ++progress->tilesDone;
    });
  };

  std::vector<PathlineGroup> rowGroups, columnGroups;
  for (int r0 = 0; r0 < n && !cancelled(); r0 += rowNodes) {
    read(r0, rowGroups, std::min(rowNodes, n - r0));
    const std::vector<GroupArrays> rows = arraysOf(rowGroups);
    const int rowTiles = (int(rows.size()) + kCostTile - 1) / kCostTile;
    // The block's own pairs: tiles (a, b), a <= b, both in the row block.
    std::vector<std::pair<int, int>> tiles;
    for (int a = 0; a < rowTiles; ++a)
      for (int b = a; b < rowTiles; ++b) tiles.emplace_back(a, b);
    pairTiles(rows, r0, tiles, rows, r0);
    // Every column block after it.
    for (int c0 = r0 + int(rows.size()); c0 < n && !cancelled(); c0 += columnNodes) {
      read(c0, columnGroups, std::min(columnNodes, n - c0));
      const std::vector<GroupArrays> cols = arraysOf(columnGroups);
      tiles.clear();
      for (int a = 0; a < rowTiles; ++a)
        for (int b = 0; b * kCostTile < int(cols.size()); ++b) tiles.emplace_back(a, b);
      pairTiles(rows, r0, tiles, cols, c0);
    }
  }
  s.seconds = since(start);
  if (stats) *stats = s;
  if (cancelled()) return CostMatrix();
  return cost;
}

}  // namespace plume
