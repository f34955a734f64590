/// \file node_files.cpp
/// Nodes of a flow graph read from the states' pathline files (§4.2-4.3).

#include "flowgraph/node_files.h"

#include "core/parallel.h"
#include "flowgraph/state_nodes.h"

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

namespace plume {

NodeFiles::NodeFiles(std::vector<const PathlineFile*> states) : mFiles(std::move(states)) {
  if (mFiles.empty()) throw std::invalid_argument("states: a flow graph needs at least one pathline file");
  std::vector<int> counts;
  for (std::size_t s = 0; s < mFiles.size(); ++s) {
    const PathlineFile* f = mFiles[s];
    if (!f) throw std::invalid_argument("state " + std::to_string(s) + " has no pathline file (null)");
    if (f->nodeCount() < 1)
      throw std::invalid_argument("state " + std::to_string(s) + " (" + f->path() + ") holds no pathline group");
    requireStateLayout(int(s), f->layout(), mFiles.front()->layout());
    counts.push_back(f->nodeCount());
  }
  mLayout = mFiles.front()->layout();
  mOffsets = stateOffsets(counts);
}

std::vector<int> NodeFiles::counts() const {
  std::vector<int> c;
  for (const PathlineFile* f : mFiles) c.push_back(f->nodeCount());
  return c;
}

void NodeFiles::read(int n, PathlineGroup& out) const {
  if (n < 0 || n >= size())
    throw std::out_of_range("node " + std::to_string(n) + " of a flow graph of " + std::to_string(size()) + " nodes");
  const int s = int(std::upper_bound(mOffsets.begin(), mOffsets.end(), n) - mOffsets.begin()) - 1;
  mFiles[std::size_t(s)]->readGroup(n - mOffsets[std::size_t(s)], out, s);
}

void NodeFiles::read(int first, std::vector<PathlineGroup>& out) const {
  parallelFor(0, int(out.size()), [&](int q) { read(first + q, out[std::size_t(q)]); });
}

}  // namespace plume
