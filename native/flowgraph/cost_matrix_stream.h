#pragma once
/// \file cost_matrix_stream.h
/// The cost matrix C of eq. 9-10 ([Graph Fire Synthesis] §4.3) streamed from the states'
/// pathline files: the groups are read block by block, so the build holds a bounded number of
/// groups (not all N, 3 GB for 1,000 nodes of 3,200 pathlines × 48 samples).

#include "flowgraph/cost_matrix.h"
#include "flowgraph/flow_graph_params.h"
#include "flowgraph/node_files.h"

#include <cstddef>

namespace plume {

/// How many groups the streamed build holds. Rows are taken in blocks of R nodes (held while
/// every column after them streams past in blocks of `columnNodes`): each group is read once
/// as a row and once per row block before it as a column, about N + N²/(2R) reads in all,
/// holding R + columnNodes groups (5 |Ω| L floats each). For a given memory, a tall row block
/// and a narrow column block read least. Measured at N = 1,000, |Ω| = 3,200, L = 48 (3.1 MB a
/// group, 2 threads, a loaded 2-core machine): R = 160 and 64 columns held 712 MB at peak and
/// spent 14% of the build reading 3,640 groups; the defaults hold as many groups (224) as that
/// and read 3,120 (see examples/flowgraph_fire/README.md for the figures).
struct CostStreamParams {
  /// Bytes for the row block: R = the largest multiple of kCostTile groups that fits (at least
  /// kCostTile). 600 MiB holds R = 192 groups of |Ω| = 3,200 × L = 48.
  std::size_t rowBlockBytes = std::size_t(600) << 20;
  /// Column block, rounded up to a multiple of kCostTile: 32 groups give R/32 tasks per block
  /// (6 at R = 192), enough for two threads; wider blocks only add memory.
  int columnNodes = 32;
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
