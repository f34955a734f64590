/// \file fuzz_vdb_frame.cpp
/// libFuzzer target: the bytes as a VDB volume frame read back by Plume (vdbGridNames, then
/// readVdbGrid of each grid listed and of the frame's grid names). The contract: a
/// std::runtime_error naming the file, or a result; anything else (another exception, a crash,
/// a stall, unbounded memory) is a finding. Seeds: make_seeds.cpp (vdb_seeds.h).

#include <cstdint>
#include <cstdio>
#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>
#include <unistd.h>
#include <vector>

#include "fuzz_common.h"
#include "io/vdb_frame.h"

namespace {

plume::fuzz::TempInput& input() {
  static plume::fuzz::TempInput file("vdb_frame", ".vdb");
  return file;
}

const std::string& inputPath() { return input().path(); }

void expectNamed(const std::runtime_error& e) {
  if (std::string(e.what()).find(inputPath()) == std::string::npos) {
    std::fprintf(stderr, "error without the file name: %s\n", e.what());
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  input().write(data, size);
  std::vector<std::string> names = {"density", "temperature", "flame", "velocity"};
  try {
    const std::vector<std::string> listed = plume::vdbGridNames(inputPath());
    names.insert(names.end(), listed.begin(), listed.begin() + std::min<std::size_t>(listed.size(), 4));
  } catch (const std::runtime_error& e) {
    expectNamed(e);
  }
  for (const std::string& name : names) {
    try {
      plume::readVdbGrid(inputPath(), name);
    } catch (const std::runtime_error& e) {
      expectNamed(e);
    }
  }
  return 0;
}
