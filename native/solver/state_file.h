#pragma once
/// \file state_file.h
/// Solver checkpoint for resuming a bake: a versioned binary file holding every grid of the
/// state (face velocities, scalars) and the frame number. Sizes are checked on read.

#include "solver/smoke_solver.h"

#include <string>

namespace plume {

/// Writes the solver state (atomically: temporary name, then rename).
void writeState(const std::string& path, const SmokeSolver& solver);

/// Reads a checkpoint into `solver`, whose resolution must match. Throws std::runtime_error on a
/// missing, truncated, corrupt or mismatched file, leaving the solver unchanged.
void readState(const std::string& path, SmokeSolver& solver);

}  // namespace plume
