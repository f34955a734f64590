#include "solver/active_box.h"

#include "core/parallel.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace plume {

ActiveBox ActiveBox::united(const ActiveBox& o) const {
  if (o.empty()) return *this;
  if (empty()) return o;
  return {glm::min(lo, o.lo), glm::max(hi, o.hi)};
}

ActiveBox ActiveBox::withCells(glm::ivec3 cellLo, glm::ivec3 cellHi, glm::ivec3 resolution) const {
  const ActiveBox cells{glm::max(cellLo, glm::ivec3(0)), glm::min(cellHi + 1, resolution)};
  return united(cells);
}

ActiveBox uniteActive(const ActiveBox& box, const ScalarGrid& grid, float background,
                      float threshold, glm::ivec3 offset) {
  const glm::ivec3 n = grid.size();
  // One box per slice, then a min/max over the slices: the same result in any order.
  std::vector<ActiveBox> slices(std::size_t(std::max(n.z, 0)));
  parallelFor(0, n.z, [&](int k) {
    glm::ivec3 lo(n.x, n.y, k), hi(-1, -1, k);
    bool any = false;
    for (int j = 0; j < n.y; ++j) {
      const float* row = &grid(0, j, k);
      int first = -1, last = -1;
      for (int i = 0; i < n.x; ++i)
        if (std::fabs(row[i] - background) > threshold) {
          if (first < 0) first = i;
          last = i;
        }
      if (first < 0) continue;
      any = true;
      lo.x = std::min(lo.x, first);
      hi.x = std::max(hi.x, last);
      lo.y = std::min(lo.y, j);
      hi.y = std::max(hi.y, j);
    }
    if (any) slices[std::size_t(k)] = {lo + offset, hi + offset + 1};
  });
  ActiveBox result = box;
  for (const ActiveBox& s : slices) result = result.united(s);
  return result;
}

ActiveBox padBox(const ActiveBox& box, int margin, glm::ivec3 resolution) {
  const int b = kActiveBoxBlock;
  ActiveBox out;
  for (int a = 0; a < 3; ++a) {
    const int lo = box.lo[a] - margin, hi = box.hi[a] + margin;
    // Floor and ceiling to whole blocks (lo may be negative before the clamp).
    const int qlo = lo >= 0 ? lo / b * b : -((-lo + b - 1) / b) * b;
    const int qhi = (hi + b - 1) / b * b;
    out.lo[a] = std::clamp(qlo, 0, resolution[a]);
    out.hi[a] = std::clamp(qhi, 0, resolution[a]);
  }
  return out;
}

template <typename T>
void copyToBox(const Grid3<T>& full, Grid3<T>& box, glm::ivec3 offset) {
  const glm::ivec3 n = box.size();
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j)
      std::copy_n(&full(offset.x, offset.y + j, offset.z + k), n.x, &box(0, j, k));
  });
}

template <typename T>
void copyFromBox(const Grid3<T>& box, Grid3<T>& full, glm::ivec3 offset) {
  const glm::ivec3 n = box.size();
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j)
      std::copy_n(&box(0, j, k), n.x, &full(offset.x, offset.y + j, offset.z + k));
  });
}

template void copyToBox<float>(const ScalarGrid&, ScalarGrid&, glm::ivec3);
template void copyToBox<glm::vec3>(const VectorGrid&, VectorGrid&, glm::ivec3);
template void copyFromBox<float>(const ScalarGrid&, ScalarGrid&, glm::ivec3);

void fillLeftBehind(ScalarGrid& full, glm::ivec3 oldOffset, glm::ivec3 oldSize,
                    glm::ivec3 newOffset, glm::ivec3 newSize, float value,
                    const ScalarGrid* ambient) {
  const glm::ivec3 newEnd = newOffset + newSize;
  parallelFor(0, oldSize.z, [&](int kk) {
    const int k = oldOffset.z + kk;
    const bool kIn = k >= newOffset.z && k < newEnd.z;
    for (int j = oldOffset.y; j < oldOffset.y + oldSize.y; ++j) {
      const bool jkIn = kIn && j >= newOffset.y && j < newEnd.y;
      for (int i = oldOffset.x; i < oldOffset.x + oldSize.x; ++i) {
        if (jkIn && i >= newOffset.x && i < newEnd.x) continue;
        full(i, j, k) = ambient ? (*ambient)(i, j, k) : value;
      }
    }
  });
}

}  // namespace plume
