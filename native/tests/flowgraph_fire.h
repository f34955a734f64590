#pragma once
/// \file flowgraph_fire.h
/// A small fire ([Graph Fire Synthesis] §4.1: combustion with a fuel-injection region) shared
/// by the flow-graph synthesis tests and benchmark: a cubic domain, a square burner of fuel
/// cells near the closed floor, open elsewhere.

#include "solver/emitters.h"
#include "solver/smoke_params.h"
#include "solver/smoke_solver.h"

namespace plume::testing {

/// n³ cells over one metre, burning, 24 frames per second.
inline SmokeParams fireParams(int n, int threads = 0) {
  SmokeParams p;
  p.resolution = glm::ivec3(n);
  p.cellSize = 1.f / float(n);
  p.combustion = true;
  p.threads = threads;
  return p;
}

/// The burner: `side` x `side` cells, 2 cells high, centred on the floor one cell above it.
inline CellSet fireBurner(int n, int side) {
  CellSet cells;
  const int lo = (n - side) / 2;
  for (int k = 1; k < 3; ++k)
    for (int j = lo; j < lo + side; ++j)
      for (int i = lo; i < lo + side; ++i)
        cells.cells.push_back(std::uint32_t(i + n * (j + n * k)));
  return cells;
}

/// What the burner injects: fuel, a little smoke, an upward push.
inline SourceSettings fireFuel() {
  SourceSettings s;
  s.fuel = 1.f;
  s.density = 0.2f;
  s.temperature = 0.5f;
  s.velocity = glm::vec3(0.f, 0.f, 0.5f);
  return s;
}

}  // namespace plume::testing
