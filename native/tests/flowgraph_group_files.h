#pragma once
/// \file flowgraph_group_files.h
/// The synthetic groups of flowgraph_groups.h written to one pathline file per state
/// ([Graph Fire Synthesis] §4.2), one group at a time: a graph far larger than memory can be
/// written, then streamed (cost_matrix_stream.h).

#include "flowgraph/pathline_file.h"
#include "tests/flowgraph_groups.h"

#include <string>
#include <vector>

namespace plume::testing {

/// Writes state s's counts[s] oscillatingGroup()s (the same groups, bit for bit, as
/// oscillatingGroups(counts, ...) when float16 is false) to "<prefix><s>.bin"; returns the paths.
inline std::vector<std::string> writeOscillatingFiles(const std::string& prefix, const std::vector<int>& counts,
                                                      int particles, int samples, std::uint64_t seed,
                                                      float noise = 0.05f, bool float16 = false) {
  std::vector<std::string> paths;
  PathlineGroup g;
  int index = 0;
  for (std::size_t s = 0; s < counts.size(); ++s) {
    PathlineFileInfo info;
    info.layout = {particles, samples, 1.f / 48.f};
    info.resolution = glm::ivec3(32, 32, 48);
    info.cellSize = 0.05f;
    info.float16 = float16;
    paths.push_back(prefix + std::to_string(s) + ".bin");
    PathlineFileWriter w(paths.back(), info);
    for (int k = 0; k < counts[s]; ++k) {
      oscillatingGroup(int(s), k, index++, particles, samples, seed, noise, g);
      w.append(g);
    }
    w.finish();
  }
  return paths;
}

/// The files at `paths`, opened.
inline std::vector<PathlineFile> openFiles(const std::vector<std::string>& paths) {
  std::vector<PathlineFile> f;
  for (const std::string& p : paths) f.push_back(PathlineFile::open(p));
  return f;
}

/// Pointers to the files, the form NodeFiles takes.
inline std::vector<const PathlineFile*> filePointers(const std::vector<PathlineFile>& files) {
  std::vector<const PathlineFile*> p;
  for (const PathlineFile& f : files) p.push_back(&f);
  return p;
}

}  // namespace plume::testing
