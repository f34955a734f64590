#pragma once
/// \file fuzz_fixtures.h
/// The small objects both the fuzz targets and the seed writer (make_seeds.cpp) use: a reader
/// that checks a file against a solver or tracer must get the same settings the seeds were
/// written with, or every seed would be refused at the header and the fuzzer would learn nothing.

#include "flowgraph/pathline_file.h"
#include "solver/smoke_solver.h"
#include "tracers/streak_tracer.h"

#include <array>

namespace plume::fuzz {

/// A 6 x 5 x 4 solver (small: a successful read is followed by one step in fuzz_state).
inline SmokeParams stateParams() {
  SmokeParams p;
  p.resolution = glm::ivec3(6, 5, 4);
  p.cellSize = 1.f / 6.f;
  p.frameDt = 1.f / 24.f;
  p.maxPressureIterations = 50;
  return p;
}

/// The tracer of fuzz_tracer_state: 8³ cells of 1/8, emission every 2 steps, open but the floor.
inline GridFrame tracerGrid() {
  return GridFrame{glm::ivec3(8), 0.125f, glm::vec3(0.f), 1.f / 24.f};
}
inline std::array<Boundary, 6> tracerSides() {
  return {Boundary::Open, Boundary::Open, Boundary::Open, Boundary::Open, Boundary::Closed,
          Boundary::Open};
}
inline StreakTracer makeTracer() {
  StreakParams p;
  p.emissionPeriod = 2;
  return StreakTracer(p, tracerGrid(), tracerSides());
}

/// A pathline file header of 3 particles x 4 samples (float16 or float32 samples).
inline PathlineFileInfo pathlineInfo(bool float16) {
  PathlineFileInfo info;
  info.layout.particles = 3;
  info.layout.samples = 4;
  info.layout.sampleDt = 0.02f;
  info.resolution = glm::ivec3(8, 8, 12);
  info.cellSize = 0.05f;
  info.origin = glm::vec3(-0.2f, -0.2f, 0.f);
  info.nodesPerFrame = 2;
  info.float16 = float16;
  return info;
}

}  // namespace plume::fuzz
