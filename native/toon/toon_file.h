#pragma once
/// \file toon_file.h
/// Per-frame toon particle cache `toon_####.bin` ([Cartoon Smoke] §2.3: the particles and the
/// flow quantities that drive their size, colour, rotation and stretch): a versioned binary file
/// holding one ToonParticleState, sizes checked against the file size before anything is
/// allocated. Angle and stretch depend on the camera and are computed when the scene is built.

#include "toon/toon_particles.h"

#include <string>

namespace plume {

/// "toon_0007.bin" for frame 7 (DESIGN.md cache naming `<kind>_<frame:04d>.<ext>`).
std::string toonFileName(int frame);

/// Writes the particles atomically (temporary name, then rename). Throws std::invalid_argument
/// if the state is inconsistent (ToonParticleState::validate) and std::runtime_error naming the
/// path if the file cannot be written.
void writeToonFile(const std::string& path, const ToonParticleState& state);

/// Reads particles. Throws std::runtime_error naming the path on a missing, truncated, corrupt
/// (bad magic, checksum, sizes, values) or newer-version file.
ToonParticleState readToonFile(const std::string& path);

}  // namespace plume
