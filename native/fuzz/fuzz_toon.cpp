/// \file fuzz_toon.cpp
/// Fuzz target of the toon particle cache reader (toon/toon_file.h): readToonFile on any bytes
/// returns a state that passes ToonParticleState::validate or throws std::runtime_error naming
/// the file.

#include "fuzz_common.h"
#include "toon/toon_file.h"

#include <stdexcept>

using namespace plume;

PLUME_FUZZ_RESIGNING_MUTATOR(fuzz::resignTrailer)

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::TempInput input("toon");
  const std::string& path = input.write(data, size);
  ToonParticleState s;
  if (!fuzz::expectClean(path, [&] { s = readToonFile(path); })) return 0;
  try {
    s.validate();
  } catch (const std::invalid_argument& e) {
    fuzz::finding(std::string("readToonFile returned an invalid state: ") + e.what());
  }
  return 0;
}
