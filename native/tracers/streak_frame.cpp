#include "tracers/streak_frame.h"

#include <stdexcept>
#include <string>

namespace plume {

std::vector<std::size_t> StreakFrame::offsets() const {
  std::vector<std::size_t> o(counts.size() + 1, 0);
  for (std::size_t s = 0; s < counts.size(); ++s) o[s + 1] = o[s] + std::size_t(counts[s]);
  return o;
}

void StreakFrame::validate() const {
  std::size_t total = 0;
  for (std::size_t s = 0; s < counts.size(); ++s) {
    if (counts[s] < 0)
      throw std::invalid_argument("streak frame: counts[" + std::to_string(s) + "] is negative");
    total += std::size_t(counts[s]);
  }
  if (groups.size() != counts.size())
    throw std::invalid_argument("streak frame: " + std::to_string(groups.size()) + " groups for " +
                                std::to_string(counts.size()) + " sources");
  if (positions.size() != total || density.size() != total || outside.size() != total)
    throw std::invalid_argument(
        "streak frame: counts sum to " + std::to_string(total) + " particles but there are " +
        std::to_string(positions.size()) + " positions, " + std::to_string(density.size()) +
        " densities and " + std::to_string(outside.size()) + " outside flags");
}

}  // namespace plume
