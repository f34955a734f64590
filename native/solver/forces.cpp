#include "solver/forces.h"

#include "core/parallel.h"
#include "solver/face_loops.h"
#include "solver/pressure.h"

#include <algorithm>
#include <cmath>

namespace plume {
namespace {

/// Linear offsets of row (j, k) and of its neighbour rows along y and z, clamped at the sides.
struct ClampedRows {
  std::size_t row, ym, yp, zm, zp;
};
inline ClampedRows clampedRows(glm::ivec3 n, int j, int k) {
  auto at = [&](int jj, int kk) {
    jj = glm::clamp(jj, 0, n.y - 1);
    kk = glm::clamp(kk, 0, n.z - 1);
    return std::size_t(n.x) * (std::size_t(jj) + std::size_t(n.y) * kk);
  };
  return {at(j, k), at(j - 1, k), at(j + 1, k), at(j, k - 1), at(j, k + 1)};
}

}  // namespace

void addBuoyancy(MacGrid3& velocity, const ScalarGrid& density, const ScalarGrid& temperature,
                 const FlagGrid* types, const SmokeParams& p, float dt) {
  if (p.alpha == 0.f && p.beta == 0.f) return;
  const glm::vec3 up = -p.gravity;  // buoyancy pushes against gravity
  const float* __restrict rho = density.data();
  const float* __restrict temp = temperature.data();
  for (int a = 0; a < 3; ++a) {
    if (up[a] == 0.f) continue;  // no buoyancy across gravity
    const float scale = dt * up[a];
    forEachFluidFace(velocity, types, a, [&](float& u, std::size_t lo, std::size_t hi) {
      const float r = 0.5f * (rho[lo] + rho[hi]);
      const float heat = 0.5f * (temp[lo] + temp[hi]) - p.ambientTemperature;
      u += scale * (p.alpha * r + p.beta * heat);
    });
  }
}

void addWind(MacGrid3& velocity, const VectorGrid& field, const FlagGrid* types,
             const SmokeParams& p, float dt) {
  if (p.windStrength == 0.f) return;
  // Implicit relaxation towards the wind: stable for any k_w dt.
  const float blend = 1.f - std::exp(-p.windStrength * dt);
  const bool perCell = field.count() != 0;
  for (int a = 0; a < 3; ++a)
    forEachFluidFace(velocity, types, a, [&](float& u, std::size_t lo, std::size_t hi) {
      const float target = perCell ? 0.5f * (field[lo][a] + field[hi][a]) : p.wind[a];
      u += blend * (target - u);
    });
}

void addVorticityConfinement(MacGrid3& velocity, const FlagGrid* types,
                             const Confinement& strength, float cellSize, float dt,
                             VectorGrid& omega, VectorGrid& force, ScalarGrid& magnitude) {
  if (!strength.any()) return;
  const float* fuel = strength.fuel && strength.flameEpsilon != 0.f ? strength.fuel->data() : nullptr;
  const glm::ivec3 n = velocity.cells();
  const float inv2h = 0.5f / cellSize;
  const std::size_t slice = std::size_t(n.x) * n.y;
  // Cell-centred velocity, once per cell (in `force`, free until the force is computed).
  VectorGrid& centre = force;
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) centre(i, j, k) = velocity.cellCenter(i, j, k);
  });
  // ω = ∇ × u by central differences of cell-centred velocity (clamped at the sides), and |ω|.
  parallelFor(0, n.z, [&](int k) {
    const glm::vec3* c = centre.data();
    for (int j = 0; j < n.y; ++j) {
      const ClampedRows r = clampedRows(n, j, k);
      for (int i = 0; i < n.x; ++i) {
        const std::size_t im = i > 0 ? i - 1 : 0, ip = i + 1 < n.x ? i + 1 : i;
        const glm::vec3 xp = c[r.row + ip], xm = c[r.row + im];
        const glm::vec3 yp = c[r.yp + i], ym = c[r.ym + i];
        const glm::vec3 zp = c[r.zp + i], zm = c[r.zm + i];
        const glm::vec3 w = inv2h * glm::vec3((yp.z - ym.z) - (zp.y - zm.y),
                                              (zp.x - zm.x) - (xp.z - xm.z),
                                              (xp.y - xm.y) - (yp.x - ym.x));
        omega[r.row + i] = w;
        magnitude[r.row + i] = glm::length(w);
      }
    }
  });
  // f = ε Δx (N × ω), N the normalised gradient of |ω|, ε = ε + ε_f min(F, 1) per cell.
  parallelFor(0, n.z, [&](int k) {
    const float* m = magnitude.data();
    for (int j = 0; j < n.y; ++j) {
      const ClampedRows r = clampedRows(n, j, k);
      for (int i = 0; i < n.x; ++i) {
        const std::size_t c = r.row + i;
        if (types && (*types)[c] != kFluid) {
          force[c] = glm::vec3(0.f);
          continue;
        }
        const std::size_t im = i > 0 ? i - 1 : 0, ip = i + 1 < n.x ? i + 1 : i;
        glm::vec3 grad(m[r.row + ip] - m[r.row + im], m[r.yp + i] - m[r.ym + i],
                       m[r.zp + i] - m[r.zm + i]);
        const float len = glm::length(grad);
        if (len < 1e-20f) {
          force[c] = glm::vec3(0.f);
          continue;
        }
        grad /= len;
        const float epsilon =
            strength.epsilon + (fuel ? strength.flameEpsilon * std::min(fuel[c], 1.f) : 0.f);
        force[c] = epsilon * cellSize * glm::cross(grad, omega[c]);
      }
    }
  });
  // u += Δt × the force averaged onto the faces between two fluid cells, the three components in
  // one pass: slice k holds the x and y faces of its cells and the z faces below them.
  float* __restrict fu = &velocity.component(0)(0, 0, 0);
  float* __restrict fv = &velocity.component(1)(0, 0, 0);
  float* __restrict fw = &velocity.component(2)(0, 0, 0);
  const glm::ivec3 su = velocity.component(0).size(), sv = velocity.component(1).size();
  const glm::ivec3 sw = velocity.component(2).size();
  const float* __restrict f = &force.data()[0][0];
  const float h = dt * 0.5f;
  // Face i of a row, between cells c - d and c (c = row + i): u_i += h (f_{c-d} + f_c) on
  // component a, where both cells are fluid (without types the loop runs without tests).
  auto faces = [&](float* __restrict u, std::size_t row, std::size_t d, int a, int i0) {
    if (!types) {
      for (int i = i0; i < n.x; ++i) u[i] += h * (f[3 * (row + i - d) + a] + f[3 * (row + i) + a]);
      return;
    }
    for (int i = i0; i < n.x; ++i)
      if ((*types)[row + i - d] == kFluid && (*types)[row + i] == kFluid)
        u[i] += h * (f[3 * (row + i - d) + a] + f[3 * (row + i) + a]);
  };
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j) {
      const std::size_t row = std::size_t(n.x) * j + slice * std::size_t(k);
      faces(fu + std::size_t(su.x) * (std::size_t(j) + std::size_t(su.y) * k), row, 1, 0, 1);
      if (j > 0)
        faces(fv + std::size_t(sv.x) * (std::size_t(j) + std::size_t(sv.y) * k), row, n.x, 1, 0);
      if (k > 0)
        faces(fw + std::size_t(sw.x) * (std::size_t(j) + std::size_t(sw.y) * k), row, slice, 2, 0);
    }
  });
}

}  // namespace plume
