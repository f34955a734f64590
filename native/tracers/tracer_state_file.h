#pragma once
/// \file tracer_state_file.h
/// Streakline tracer checkpoint for resuming a traced bake ([Smoke Surfaces] §3.2): a versioned
/// binary file holding a StreakTracer's settings and its whole StreakTracerState (point sources,
/// particles, density, outside flags, exit velocities, emission count, steps, the pause switch of
/// Figure 10 and the step of the youngest emission), written next to the
/// solver's state file (solver/state_file.h) for the same frame. Sizes are checked on read.

#include "tracers/streak_tracer.h"

#include <string>

namespace plume {

/// Writes the tracer's settings and state atomically (temporary name, then rename), labelled with
/// `frame` (the frame of the bake it belongs to). Throws std::runtime_error naming the path if it
/// cannot be written.
void writeTracerState(const std::string& path, const StreakTracer& tracer, int frame);

/// Reads a checkpoint into `tracer`, whose settings (emission period, interpolation, domain box,
/// boundaries) must be those the file was written with; returns the frame label. Throws
/// std::runtime_error naming the path on a missing, truncated, corrupt, newer or mismatched file,
/// leaving the tracer unchanged.
int readTracerState(const std::string& path, StreakTracer& tracer);

}  // namespace plume
