#include "solver/forces.h"

#include "core/parallel.h"
#include "solver/pressure.h"

#include <cmath>

namespace plume {
namespace {

/// Calls body(u, lo, hi) for every face u of component `a` between two fluid cells (linear
/// indices lo, hi: the cells below and above the face), row by row; the sides of the domain are
/// left to the boundary conditions. types == nullptr: every cell is fluid, and the rows run
/// without a test per face (they vectorize).
template <typename Body>
void forEachFluidFace(MacGrid3& velocity, const FlagGrid* types, int a, const Body& body) {
  const glm::ivec3 n = velocity.cells();
  ScalarGrid& comp = velocity.component(a);
  const glm::ivec3 fs = comp.size();
  const std::ptrdiff_t stride = a == 0 ? 1 : (a == 1 ? std::ptrdiff_t(n.x) : std::ptrdiff_t(n.x) * n.y);
  // Along x the faces of a row between two cells are 1 .. nx-1; along y and z whole rows.
  const int i0 = a == 0 ? 1 : 0, i1 = a == 0 ? n.x : fs.x;
  parallelFor(0, fs.z, [&](int k) {
    if (a == 2 && (k == 0 || k == n.z)) return;
    for (int j = 0; j < fs.y; ++j) {
      if (a == 1 && (j == 0 || j == n.y)) continue;
      float* __restrict u = &comp(0, j, k);
      // Cell (i, j, k) is above face (i, j, k) on every axis.
      const std::size_t row = std::size_t(n.x) * (std::size_t(j) + std::size_t(n.y) * k);
      if (!types) {
        for (int i = i0; i < i1; ++i) body(u[i], row + i - stride, row + i);
        continue;
      }
      for (int i = i0; i < i1; ++i) {
        const std::size_t hi = row + i, lo = hi - stride;
        if ((*types)[lo] == kFluid && (*types)[hi] == kFluid) body(u[i], lo, hi);
      }
    }
  });
}

/// Clamped linear index of cell (i, j, k) in a grid of n cells.
inline std::size_t clampedIndex(glm::ivec3 n, int i, int j, int k) {
  i = glm::clamp(i, 0, n.x - 1);
  j = glm::clamp(j, 0, n.y - 1);
  k = glm::clamp(k, 0, n.z - 1);
  return std::size_t(i) + std::size_t(n.x) * (std::size_t(j) + std::size_t(n.y) * k);
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

void addVorticityConfinement(MacGrid3& velocity, const FlagGrid* types, float epsilon,
                             float cellSize, float dt, VectorGrid& omega, VectorGrid& force,
                             ScalarGrid& magnitude) {
  if (epsilon == 0.f) return;
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
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const glm::vec3 xp = centre[clampedIndex(n, i + 1, j, k)], xm = centre[clampedIndex(n, i - 1, j, k)];
        const glm::vec3 yp = centre[clampedIndex(n, i, j + 1, k)], ym = centre[clampedIndex(n, i, j - 1, k)];
        const glm::vec3 zp = centre[clampedIndex(n, i, j, k + 1)], zm = centre[clampedIndex(n, i, j, k - 1)];
        const glm::vec3 w = inv2h * glm::vec3((yp.z - ym.z) - (zp.y - zm.y),
                                              (zp.x - zm.x) - (xp.z - xm.z),
                                              (xp.y - xm.y) - (yp.x - ym.x));
        omega(i, j, k) = w;
        magnitude(i, j, k) = glm::length(w);
      }
  });
  // f = ε Δx (N × ω), N the normalised gradient of |ω|.
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const std::size_t c = std::size_t(i) + std::size_t(n.x) * j + slice * std::size_t(k);
        if (types && (*types)[c] != kFluid) {
          force[c] = glm::vec3(0.f);
          continue;
        }
        auto mag = [&](int a, int b, int d) { return magnitude[clampedIndex(n, a, b, d)]; };
        glm::vec3 grad(mag(i + 1, j, k) - mag(i - 1, j, k), mag(i, j + 1, k) - mag(i, j - 1, k),
                       mag(i, j, k + 1) - mag(i, j, k - 1));
        const float len = glm::length(grad);
        if (len < 1e-20f) {
          force[c] = glm::vec3(0.f);
          continue;
        }
        grad /= len;
        force[c] = epsilon * cellSize * glm::cross(grad, omega[c]);
      }
  });
  for (int a = 0; a < 3; ++a)
    forEachFluidFace(velocity, types, a, [&](float& u, std::size_t lo, std::size_t hi) {
      u += dt * 0.5f * (force[lo][a] + force[hi][a]);
    });
}

}  // namespace plume
