#pragma once
/// \file tracer_driver.h
/// Runs a solver frame with streakline tracers attached ([Smoke Surfaces] §3.2: particles are
/// advected with the simulation, their data stored every time step), without touching the solver.

#include "solver/smoke_solver.h"
#include "tracers/streak_tracer.h"

namespace plume {

/// SmokeSolver::advanceFrame() with the tracer observing every step: the velocity is copied into
/// tracer.previousVelocity() before each step and tracer.observeStep() runs after it. Returns
/// false when solver.cancel() or tracer.cancel() was called: both are then mid-frame and must be
/// discarded, as with advanceFrame().
bool advanceFrameWithTracers(SmokeSolver& solver, StreakTracer& tracer);

}  // namespace plume
