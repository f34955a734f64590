/// \file fuzz_state.cpp
/// Fuzz target of the solver checkpoint reader (solver/state_file.h): readState on any bytes
/// returns or throws std::runtime_error naming the file; after a successful read the solver
/// takes one step (a checksum-valid file with hostile values must not crash it).

#include "fuzz_common.h"
#include "fuzz_fixtures.h"
#include "solver/state_file.h"

using namespace plume;

PLUME_FUZZ_RESIGNING_MUTATOR(fuzz::resignTrailer)

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::TempInput input("state");
  static SmokeSolver solver(fuzz::stateParams());
  const std::string& path = input.write(data, size);
  if (fuzz::expectClean(path, [&] { readState(path, solver); })) solver.step(0.01f);
  return 0;
}
