#pragma once
/// \file streak_shot.h
/// A synthetic shot of streaklines for the streak-surface fit tests: every frame's particles
/// laid out as the add-on's streakline_grid (points[f][b * particles + a], oldest first) with
/// the keep flags of fit_mask, and the StreakGrid views chooseNetSize() and fitShot() take.

#include "nurbs/surface_fit.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace plume {

struct StreakShot {
  int lines = 0, particles = 0;
  std::vector<std::vector<glm::vec3>> points;  ///< per frame, lines × particles
  std::vector<std::vector<std::uint8_t>> keep;  ///< per frame, 1 where the sheet goes through
  std::vector<StreakGrid> grids() const {
    std::vector<StreakGrid> g;
    for (std::size_t f = 0; f < points.size(); ++f)
      g.push_back({points[f].data(), keep[f].data(), particles, lines});
    return g;
  }
};

}  // namespace plume
