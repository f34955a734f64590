#include "solver/advection.h"

#include "core/parallel.h"

namespace plume {
namespace {

/// One semi-Lagrangian pass: dst(x) = src(traceBack(x, cells)). With `clampTo`, the result is
/// limited to the range of *clampTo around the back-traced point (BFECC's limiter).
void semiLagrangian(const ScalarGrid& src, ScalarGrid& dst, glm::vec3 offset,
                    const MacGrid3& velocity, float cells, Interpolation interpolation,
                    const ScalarGrid* clampTo) {
  const glm::ivec3 n = src.size();
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const glm::vec3 p = glm::vec3(i, j, k) + offset;
        const glm::vec3 q = traceBack(velocity, p, cells) - offset;  // into src's index space
        float value = sample(src, q, interpolation);
        if (clampTo) {
          float lo, hi;
          sampleRange(*clampTo, q, lo, hi);
          value = value < lo ? lo : (value > hi ? hi : value);
        }
        dst(i, j, k) = value;
      }
  });
}

}  // namespace

glm::vec3 traceBack(const MacGrid3& velocity, glm::vec3 p, float cells) {
  const glm::vec3 v1 = sampleVelocity(velocity, p);
  const glm::vec3 mid = p - 0.5f * cells * v1;
  const glm::vec3 v2 = sampleVelocity(velocity, mid);
  return p - cells * v2;
}

void Advector::reserve(std::size_t count) {
  mForward.reserve(count);
  mBackward.reserve(count);
}

void Advector::advect(const ScalarGrid& src, ScalarGrid& dst, glm::vec3 offset,
                      const MacGrid3& velocity, float dt, float cellSize, Advection scheme,
                      Interpolation interpolation) {
  const float cells = dt / cellSize;
  dst.reshape(src.size());
  if (scheme == Advection::SemiLagrangian) {
    semiLagrangian(src, dst, offset, velocity, cells, interpolation, nullptr);
    return;
  }
  // BFECC (Kim et al. 2005): forward, backward, then forward again from the corrected field.
  mForward.reshape(src.size());
  mBackward.reshape(src.size());
  semiLagrangian(src, mForward, offset, velocity, cells, interpolation, nullptr);    // φ̂
  semiLagrangian(mForward, mBackward, offset, velocity, -cells, interpolation, nullptr);  // φ̄
  const std::size_t count = src.count();
  const int slices = src.size().z;
  const std::size_t perSlice = count / std::size_t(slices);
  parallelFor(0, slices, [&](int k) {
    // The error estimate ½(φ - φ̄) is added to φ before the final pass.
    for (std::size_t n = std::size_t(k) * perSlice, e = n + perSlice; n < e; ++n)
      mBackward[n] = src[n] + 0.5f * (src[n] - mBackward[n]);
  });
  // The limiter clamps to the range of the original φ so no new extrema appear.
  semiLagrangian(mBackward, dst, offset, velocity, cells, interpolation, &src);
}

}  // namespace plume
