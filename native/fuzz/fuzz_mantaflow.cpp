/// \file fuzz_mantaflow.cpp
/// libFuzzer target: the bytes as a Blender Mantaflow fluid_data frame read onto the seeds'
/// domain (readMantaflowFrame). The contract: a std::runtime_error naming the file,
/// or a frame; anything else (another exception, a crash, a stall, unbounded memory) is a
/// finding. Seeds: make_seeds.cpp (vdb_seeds.h).

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>
#include <unistd.h>

#include "fuzz_common.h"
#include "fuzz/vdb_seeds.h"
#include "io/mantaflow_cache.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static plume::fuzz::TempInput input("mantaflow", ".vdb");
  const std::string& path = input.write(data, size);
  try {
    plume::readMantaflowFrame(path, plume::seeds::mantaflowGrid());
  } catch (const std::runtime_error& e) {
    if (std::string(e.what()).find(path) == std::string::npos) {
      std::fprintf(stderr, "error without the file name: %s\n", e.what());
      std::abort();
    }
  }
  return 0;
}
