#pragma once
/// \file toon_random.h
/// The random positions of the toon particles ([Cartoon Smoke] §2.1 emission, §2.3 birth):
/// one generator per (seed, frame, stage, index), so that a particle's position depends neither
/// on the thread that creates it nor on the other particles.

#include "core/rng.h"
#include "solver/emitters.h"

#include <cstdint>
#include <glm/glm.hpp>

namespace plume::toon {

/// Random streams of the stages that create particles.
enum class Stream : std::uint64_t { Emission = 1, Birth = 2, EmissionOffset = 3 };

/// The generator of one emission or birth: a seed per (frame, stage), a stream per index.
inline Rng streamRng(std::uint64_t seed, std::int64_t frame, Stream stage, std::uint64_t index) {
  const std::uint64_t key = std::uint64_t(frame) * 0x9E3779B97F4A7C15ull +
                            std::uint64_t(stage) * 0xC2B2AE3D27D4EB4Full;
  return Rng(seed ^ key, index);
}

/// A random point of the unit cube, kept 1e-3 away from its faces so that rounding never moves a
/// particle born in a cell into its neighbour (birth counts the particles per cell).
inline glm::vec3 uniform3(Rng& r) {
  constexpr double kMargin = 1e-3;
  auto u = [&] { return float(kMargin + (1.0 - 2.0 * kMargin) * r.uniform()); };
  const float x = u(), y = u(), z = u();
  return {x, y, z};
}

/// §2.3: where the particle born in cell (i, j, k) (linear index `cell`) of frame `frame` is
/// placed, uniformly at random in the cell.
inline glm::vec3 birthPosition(std::uint64_t seed, std::int64_t frame, const GridFrame& grid,
                               glm::ivec3 ijk, std::size_t cell) {
  Rng rng = streamRng(seed, frame, Stream::Birth, cell);
  return grid.origin + (glm::vec3(ijk) + uniform3(rng)) * grid.cellSize;
}

}  // namespace plume::toon
