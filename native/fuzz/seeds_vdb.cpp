/// \file seeds_vdb.cpp
/// Writes the seed corpus of the VDB fuzz targets with OpenVDB's own writer (vdb_seeds.h):
/// `seeds_vdb DIR` makes DIR/vdb_frame/ and DIR/mantaflow/, each holding a Plume volume frame
/// and Mantaflow frames in full and half precision (either reader meets both kinds).

#include <cstdio>
#include <filesystem>
#include <string>

#include "fuzz/vdb_seeds.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s CORPUS_DIR\n", argv[0]);
    return 2;
  }
  namespace fs = std::filesystem;
  for (const char* target : {"vdb_frame", "mantaflow"}) {
    const fs::path dir = fs::path(argv[1]) / target;
    fs::create_directories(dir);
    plume::seeds::writePlumeFrameSeed((dir / "frame.vdb").string());
    plume::seeds::writeMantaflowSeed((dir / "mantaflow.vdb").string(), /*half=*/false);
    plume::seeds::writeMantaflowSeed((dir / "mantaflow_half.vdb").string(), /*half=*/true);
  }
  return 0;
}
