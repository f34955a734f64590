// A temporary file or folder name unique to this test process: ctest runs test binaries in
// parallel, and the sanitizer build's tests run beside the plain build's, so no fixed name
// under the temporary folder may be shared between two processes. Every name given out is
// removed (file or folder) when the process exits.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace plume::test {

inline std::vector<std::string>& tempPaths() {
  static std::vector<std::string> paths;
  return paths;
}

inline void removeTempPaths() {
  for (const std::string& p : tempPaths()) {
    std::error_code ignored;
    std::filesystem::remove_all(p, ignored);
  }
}

/// ::testing::TempDir() + "plume_<pid>_" + name, removed at exit.
inline std::string tempPath(const std::string& name) {
  if (tempPaths().empty()) std::atexit(removeTempPaths);
  std::string path = ::testing::TempDir() + "plume_" + std::to_string(::getpid()) + "_" + name;
  tempPaths().push_back(path);
  return path;
}

}  // namespace plume::test
