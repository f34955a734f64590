#pragma once
/// \file cell_balls.h
/// Spherical cell sets for the solver tests' sources and obstacles.

#include "solver/emitters.h"

#include <glm/glm.hpp>

#include <cstdint>

namespace plume::test {

/// All cells of a grid of `res` cells whose centre lies within r cells of c (index space).
inline CellSet ball(glm::ivec3 res, glm::vec3 c, float r) {
  CellSet s;
  for (int k = 0; k < res.z; ++k)
    for (int j = 0; j < res.y; ++j)
      for (int i = 0; i < res.x; ++i)
        if (glm::length(glm::vec3(i, j, k) + 0.5f - c) <= r)
          s.cells.push_back(std::uint32_t(i + res.x * (j + res.y * k)));
  return s;
}

}  // namespace plume::test
