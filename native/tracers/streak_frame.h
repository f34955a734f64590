#pragma once
/// \file streak_frame.h
/// One frame of streaklines ([Smoke Surfaces] §3.2, Figure 2): the particles of every point
/// source in birth order, with the density sampled at each, as stored in the cache every frame.

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace plume {

/// Snapshot of all streaklines at one time. Source s owns the counts[s] particles starting at
/// sum(counts[0..s)), oldest first ("the connection follows the birth order", §3.2).
struct StreakFrame {
  std::vector<int> counts;             ///< particles per source (source ID = index)
  std::vector<glm::vec3> positions;    ///< world positions, sources concatenated
  std::vector<float> density;          ///< density sampled at each particle (§3.4)
  std::vector<int> groups;             ///< candidate group of each source (§3.3)
  std::vector<std::uint8_t> outside;   ///< 1: left through an open side (moves on with its exit velocity)

  int sourceCount() const { return int(counts.size()); }
  std::size_t particleCount() const { return positions.size(); }
  /// Offset of each source's first particle, plus the total at the end (sourceCount() + 1 values).
  std::vector<std::size_t> offsets() const;
  /// Throws std::invalid_argument when the arrays disagree in size or a count is negative.
  void validate() const;
};

}  // namespace plume
