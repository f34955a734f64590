// A temporary file or folder name unique to this test process: ctest runs test binaries in
// parallel, and the sanitizer build's tests run beside the plain build's, so no fixed name
// under the temporary folder may be shared between two processes.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

namespace plume::test {

/// ::testing::TempDir() + "plume_<pid>_" + name.
inline std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "plume_" + std::to_string(::getpid()) + "_" + name;
}

}  // namespace plume::test
