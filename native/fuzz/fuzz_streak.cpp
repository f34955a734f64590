/// \file fuzz_streak.cpp
/// Fuzz target of the streak cache reader (tracers/streak_file.h): readStreakFile on any bytes
/// returns a consistent frame (StreakFrame::validate, finite positions and densities: they
/// become grid cells in streak/candidate_pairs.cpp) or throws std::runtime_error naming the file.

#include "fuzz_common.h"
#include "tracers/streak_file.h"

#include <cmath>
#include <stdexcept>

using namespace plume;

PLUME_FUZZ_RESIGNING_MUTATOR(fuzz::resignTrailer)

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::TempInput input("streak");
  const std::string& path = input.write(data, size);
  StreakFrame f;
  if (!fuzz::expectClean(path, [&] { f = readStreakFile(path); })) return 0;
  try {
    f.validate();
  } catch (const std::invalid_argument& e) {
    fuzz::finding(std::string("readStreakFile returned an inconsistent frame: ") + e.what());
  }
  for (std::size_t i = 0; i < f.positions.size(); ++i)
    if (!std::isfinite(f.positions[i].x) || !std::isfinite(f.positions[i].y) ||
        !std::isfinite(f.positions[i].z) || !std::isfinite(f.density[i]))
      fuzz::finding("readStreakFile returned a non-finite particle " + std::to_string(i));
  for (std::uint8_t o : f.outside)
    if (o > 1) fuzz::finding("readStreakFile returned an outside flag > 1");
  return 0;
}
