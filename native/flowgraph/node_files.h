#pragma once
/// \file node_files.h
/// The nodes of a flow graph read from its states' pathline files ([Graph Fire Synthesis]
/// §4.2-4.3) instead of held in memory: node n is group k of state s in the order of
/// stateNodeCounts() (state by state, chronologically), read when it is needed.

#include "flowgraph/pathline_file.h"
#include "flowgraph/pathline_group.h"

#include <cstddef>
#include <vector>

namespace plume {

/// The pathline files of the states of one graph, as one list of nodes.
class NodeFiles {
 public:
  /// Throws std::invalid_argument when there is no file, a file is null or holds no node, or the
  /// states' layouts differ (with the messages of stateNodeCounts(), e.g. "state 1 has 3000
  /// particles per group, state 0 has 3217: ..."). The files must outlive this object.
  explicit NodeFiles(std::vector<const PathlineFile*> states);

  /// N, the nodes of all states.
  int size() const { return mOffsets.back(); }
  /// |Ω|, L and Δt_n shared by every node.
  const PathlineLayout& layout() const { return mLayout; }
  /// Nodes per state (what stateNodeCounts() gives for the groups in memory).
  std::vector<int> counts() const;
  /// Resident bytes of one decoded group (start points and the 5 |Ω| L floats of samples).
  std::size_t groupBytes() const { return 12 * std::size_t(mLayout.particles) + 20 * mLayout.values(); }

  /// Reads node n (0 <= n < size()) into `out` (buffers reused; state and step set).
  /// Thread-safe; throws what PathlineFile::readGroup() throws (the file named).
  void read(int n, PathlineGroup& out) const;
  /// Reads nodes first .. first + out.size() − 1 into out, in parallel.
  void read(int first, std::vector<PathlineGroup>& out) const;

 private:
  std::vector<const PathlineFile*> mFiles;
  std::vector<int> mOffsets;  ///< first node of each state, then N
  PathlineLayout mLayout;
};

}  // namespace plume
