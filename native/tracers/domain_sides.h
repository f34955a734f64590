#pragma once
/// \file domain_sides.h
/// What the sides of the domain do to a massless particle (streaklines, [Smoke Surfaces] §3.2;
/// pathlines, [Graph Fire Synthesis] §4.2): a closed side holds it, an open side lets it out.

#include "solver/smoke_params.h"

#include <glm/glm.hpp>

#include <array>

namespace plume {

/// Applies the sides (-x, +x, -y, +y, -z, +z) of the box [lo, hi] to a position x that may have
/// moved out of it: beyond a closed side x is clamped onto it; beyond an open side it is left
/// as is and the particle has left. Returns true when it left through an open side.
inline bool applyDomainSides(glm::vec3& x, glm::vec3 lo, glm::vec3 hi,
                             const std::array<Boundary, 6>& sides) {
  bool left = false;
  for (int a = 0; a < 3; ++a) {
    if (x[a] < lo[a]) {
      if (sides[std::size_t(2 * a)] == Boundary::Open) left = true;
      else x[a] = lo[a];
    } else if (x[a] > hi[a]) {
      if (sides[std::size_t(2 * a + 1)] == Boundary::Open) left = true;
      else x[a] = hi[a];
    }
  }
  return left;
}

}  // namespace plume
