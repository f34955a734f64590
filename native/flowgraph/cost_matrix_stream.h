#pragma once
/// \file cost_matrix_stream.h
/// The cost matrix C of eq. 9-10 (graph_fire_synthesis.txt §4.3) streamed from the states'
/// pathline files: the groups are read block by block, so the build holds a bounded number of
/// groups (not all N, 3 GB for 1,000 nodes of 3,200 pathlines × 48 samples).

#include "flowgraph/cost_matrix.h"
#include "flowgraph/flow_graph_params.h"
#include "flowgraph/node_files.h"

#include <cstddef>

namespace plume {

/// How many groups the streamed build holds. Rows are taken in blocks of R nodes (held while
/// every column after them streams past in blocks of `columnNodes`): each group is read once
/// as a row and about (its index) / R times as a column, N + N²/(2R) reads in all, holding
/// R + columnNodes groups (5 |Ω| L floats each).
struct CostStreamParams {
  /// Bytes for the row block: R = the largest multiple of kCostTile groups that fits (at least
  /// kCostTile). 512 MiB holds R = 160 groups of |Ω| = 3,200 × L = 48.
  std::size_t rowBlockBytes = std::size_t(512) << 20;
  /// Column block, a multiple of kCostTile (rounded up): 64 groups give (R/32)·2 tasks per
  /// block, enough to keep two threads busy; more only adds memory.
  int columnNodes = 64;
};

/// What a streamed build did (for benchmarks and reports).
struct CostStreamStats {
  int rowNodes = 0;            ///< R, nodes per row block
  int columnNodes = 0;         ///< nodes per column block
  long long groupReads = 0;    ///< groups read from the files (rows and columns)
  double readSeconds = 0.0;    ///< wall time spent reading (the threads idle for computing)
  double seconds = 0.0;        ///< wall time of the whole build
};

/// C of eq. 9-10 for the nodes of `nodes` (see computeCostMatrix() of cost_matrix.h): the same
/// values bit for bit as with every group in memory, at any thread count and block size (each
/// entry is summed from its two groups only, in one fixed order; cost_tiles.h). Uses
/// params.alpha, beta and threads. `progress` counts the same tiles as the in-memory build and
/// is checked for cancellation before every block and tile (a cancelled build returns a 0×0
/// matrix). Throws std::invalid_argument on bad params or stream settings, and what
/// NodeFiles::read() throws (a damaged file, named).
CostMatrix computeCostMatrix(const NodeFiles& nodes, const FlowGraphParams& params,
                             CostMatrixProgress* progress = nullptr, const CostStreamParams& stream = {},
                             CostStreamStats* stats = nullptr);

}  // namespace plume
