#include "solver/inflow.h"

#include "core/parallel.h"

#include <algorithm>

namespace plume {
namespace {

// Face grids have at most 1.5 × kMaxCells samples (n + 1 faces on an axis of n >= 2 cells): their
// indices leave the flag bits of SamplePoints free.
static_assert(1.5 * kMaxCells < double(SamplePoints::kGhost), "sample indices reach kGhost");

/// Calls body(c, w) for each sample c of the traced grid with ghost weight w > 0 in the active
/// blocks of mask. Only the flagged groups of points are read (inflow samples: few), z-slices
/// in parallel; each sample is written by one call, so the result is the same for any thread
/// count.
template <typename Body>
void forEachInflowSample(const SamplePoints& back, const BlockMask* mask, const Body& body) {
  if (back.ghostSides() == 0) return;
  constexpr std::size_t G = SamplePoints::kGhostGroup;
  constexpr int B = BlockMask::kBlock;
  const glm::ivec3 n = back.gridSize();
  const std::size_t slice = std::size_t(n.x) * std::size_t(n.y);
  const std::uint32_t* index = back.index();
  const std::uint8_t* groups = back.ghostGroups();
  const float* ghost = back.ghost();
  parallelFor(0, n.z, [&](int k) {
    const std::size_t begin = slice * std::size_t(k), end = begin + slice;
    for (std::size_t g = begin / G; g * G < end; ++g) {
      if (!groups[g]) continue;
      for (std::size_t c = std::max(begin, g * G), e = std::min(end, g * G + G); c < e; ++c) {
        if (!(index[c] & SamplePoints::kGhost)) continue;
        // Points of inactive blocks were not traced (stale); a group may straddle two rows.
        if (mask) {
          const int i = int((c - begin) % std::size_t(n.x)), j = int((c - begin) / std::size_t(n.x));
          if (!mask->active(i / B, j / B, k / B)) continue;
        }
        body(c, ghost[c]);
      }
    }
  });
}

}  // namespace

std::uint8_t openSides(const std::array<Boundary, 6>& boundaries) {
  std::uint8_t sides = 0;
  for (int s = 0; s < 6; ++s)
    if (boundaries[std::size_t(s)] == Boundary::Open) sides |= ghostSideBit(s);
  return sides;
}

void blendInflow(ScalarGrid* const* grids, std::size_t count, const float* ambient,
                 const ScalarGrid* const* ambientGrids, const SamplePoints& back,
                 const BlockMask* mask) {
  forEachInflowSample(back, mask, [&](std::size_t c, float w) {
    for (std::size_t f = 0; f < count; ++f) {
      ScalarGrid& grid = *grids[f];
      const float outside = ambientGrids[f] ? (*ambientGrids[f])[c] : ambient[f];
      // Exactly `outside` at w = 1, and unchanged where the air outside is the air inside.
      grid[c] = w >= 1.f ? outside : grid[c] + w * (outside - grid[c]);
    }
  });
}

void copyInflow(ScalarGrid* const* src, ScalarGrid* const* dst, std::size_t count,
                const SamplePoints& back, const BlockMask* mask) {
  forEachInflowSample(back, mask, [&](std::size_t c, float) {
    for (std::size_t f = 0; f < count; ++f) (*dst[f])[c] = (*src[f])[c];
  });
}

}  // namespace plume
