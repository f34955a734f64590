#include "solver/mass_conservation.h"

#include "core/parallel.h"

namespace plume {
namespace {

std::size_t sliceSize(const ScalarGrid& q) {
  return std::size_t(q.size().x) * std::size_t(q.size().y);
}

}  // namespace

double totalMass(const ScalarGrid& q) {
  const std::size_t slice = sliceSize(q);
  return parallelSum(0, q.size().z, [&](int k) {
    double s = 0.0;
    for (std::size_t c = std::size_t(k) * slice, e = c + slice; c < e; ++c) s += q[c];
    return s;
  });
}

double outflowMass(const ScalarGrid& q, const MacGrid3& velocity,
                   const std::array<Boundary, 6>& boundaries, float dt, float cellSize) {
  const glm::ivec3 n = q.size();
  const double scale = double(dt) / double(cellSize);
  double out = 0.0;
  for (int a = 0; a < 3; ++a)
    for (int side = 0; side < 2; ++side) {
      if (boundaries[2 * a + side] != Boundary::Open) continue;
      const ScalarGrid& comp = velocity.component(a);
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      // Faces of this side, in a deterministic order (rows of the side's plane).
      out += parallelSum(0, n[c], [&](int y) {
        double s = 0.0;
        for (int x = 0; x < n[b]; ++x) {
          glm::ivec3 cell(0), face(0);
          cell[b] = face[b] = x;
          cell[c] = face[c] = y;
          cell[a] = side == 0 ? 0 : n[a] - 1;
          face[a] = side == 0 ? 0 : n[a];
          const float un = comp(face.x, face.y, face.z) * (side == 0 ? -1.f : 1.f);
          if (un > 0.f) s += double(q(cell.x, cell.y, cell.z)) * un * scale;
        }
        return s;
      });
    }
  return out;
}

double restoreMass(ScalarGrid& q, double target) {
  const std::size_t slice = sliceSize(q);
  const int slices = q.size().z;
  if (target < 0.0) target = 0.0;
  const double mass = totalMass(q);
  if (mass <= 0.0) return target;
  if (mass > target) {
    const float s = float(target / mass);
    parallelFor(0, slices, [&](int k) {
      for (std::size_t c = std::size_t(k) * slice, e = c + slice; c < e; ++c) q[c] *= s;
    });
    return 0.0;
  }
  const float peak = float(parallelMax(0, slices, [&](int k) {
    float m = 0.f;
    for (std::size_t c = std::size_t(k) * slice, e = c + slice; c < e; ++c) m = q[c] > m ? q[c] : m;
    return double(m);
  }));
  if (peak <= 0.f) return target - mass;
  // Room to grow without passing the peak: Σ q (1 - q/q_max).
  const float invPeak = 1.f / peak;
  const double room = parallelSum(0, slices, [&](int k) {
    double s = 0.0;
    for (std::size_t c = std::size_t(k) * slice, e = c + slice; c < e; ++c)
      if (q[c] > 0.f) s += double(q[c]) * (1.0 - double(q[c]) * invPeak);
    return s;
  });
  if (room <= 0.0) return target - mass;
  const double wanted = (target - mass) / room;
  const float gain = float(wanted < 1.0 ? wanted : 1.0);  // q + q(1 - q/q_max) <= q_max
  parallelFor(0, slices, [&](int k) {
    for (std::size_t c = std::size_t(k) * slice, e = c + slice; c < e; ++c)
      if (q[c] > 0.f) q[c] += gain * q[c] * (1.f - q[c] * invPeak);
  });
  return wanted > 1.0 ? (target - mass) - room : 0.0;
}

}  // namespace plume
