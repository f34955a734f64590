#pragma once
/// \file streak_file.h
/// Per-frame streakline cache `streaks_####.bin` ([Smoke Surfaces] §3.2: particle positions
/// and densities "are stored at every time step"): a versioned binary file holding one
/// StreakFrame, sizes checked against the file size before anything is allocated.

#include "tracers/streak_frame.h"

#include <string>

namespace plume {

/// "streaks_0007.bin" for frame 7 (DESIGN.md cache naming `<kind>_<frame:04d>.<ext>`).
std::string streakFileName(int frame);

/// Writes a frame atomically (temporary name, then rename). Throws std::invalid_argument if the
/// frame is inconsistent (StreakFrame::validate) and std::runtime_error naming the path if the
/// file cannot be written.
void writeStreakFile(const std::string& path, const StreakFrame& frame);

/// Reads a frame. Throws std::runtime_error naming the path on a missing, truncated, corrupt
/// (bad magic, checksum, sizes, non-finite values) or newer-version file.
StreakFrame readStreakFile(const std::string& path);

}  // namespace plume
