#include "solver/forces.h"

#include "core/parallel.h"
#include "solver/pressure.h"

#include <cmath>

namespace plume {
namespace {

/// Calls body(component, i, j, k, cellA, cellB) for every interior face of axis `a` whose two
/// cells are fluid; cellA/cellB are the linear indices of the cells below/above the face.
template <typename Body>
void forEachFluidFace(MacGrid3& velocity, const FlagGrid& types, const Body& body) {
  const glm::ivec3 n = velocity.cells();
  for (int a = 0; a < 3; ++a) {
    ScalarGrid& comp = velocity.component(a);
    const glm::ivec3 fs = comp.size();
    const std::ptrdiff_t stride = a == 0 ? 1 : (a == 1 ? types.strideY() : types.strideZ());
    parallelFor(0, fs.z, [&](int k) {
      for (int j = 0; j < fs.y; ++j)
        for (int i = 0; i < fs.x; ++i) {
          const glm::ivec3 c(i, j, k);
          if (c[a] == 0 || c[a] == n[a]) continue;  // domain sides: boundary conditions decide
          const std::size_t hi = types.index(i, j, k);
          const std::size_t lo = hi - std::size_t(stride);
          if (types[lo] != kFluid || types[hi] != kFluid) continue;
          body(comp(i, j, k), a, lo, hi);
        }
    });
  }
}

}  // namespace

void addBuoyancy(MacGrid3& velocity, const ScalarGrid& density, const ScalarGrid& temperature,
                 const FlagGrid& types, const SmokeParams& p, float dt) {
  if (p.alpha == 0.f && p.beta == 0.f) return;
  const glm::vec3 up = -p.gravity;  // buoyancy pushes against gravity
  forEachFluidFace(velocity, types, [&](float& u, int a, std::size_t lo, std::size_t hi) {
    if (up[a] == 0.f) return;
    const float rho = 0.5f * (density[lo] + density[hi]);
    const float heat = 0.5f * (temperature[lo] + temperature[hi]) - p.ambientTemperature;
    u += dt * up[a] * (p.alpha * rho + p.beta * heat);
  });
}

void addWind(MacGrid3& velocity, const VectorGrid& field, const FlagGrid& types,
             const SmokeParams& p, float dt) {
  if (p.windStrength == 0.f) return;
  // Implicit relaxation towards the wind: stable for any k_w dt.
  const float blend = 1.f - std::exp(-p.windStrength * dt);
  const bool perCell = field.count() == types.count();
  forEachFluidFace(velocity, types, [&](float& u, int a, std::size_t lo, std::size_t hi) {
    const float target = perCell ? 0.5f * (field[lo][a] + field[hi][a]) : p.wind[a];
    u += blend * (target - u);
  });
}

void addVorticityConfinement(MacGrid3& velocity, const FlagGrid& types, float epsilon,
                             float cellSize, float dt, VectorGrid& omega, VectorGrid& force) {
  if (epsilon == 0.f) return;
  const glm::ivec3 n = velocity.cells();
  const float inv2h = 0.5f / cellSize;
  auto centre = [&](int i, int j, int k) {
    i = glm::clamp(i, 0, n.x - 1);
    j = glm::clamp(j, 0, n.y - 1);
    k = glm::clamp(k, 0, n.z - 1);
    return velocity.cellCenter(i, j, k);
  };
  // ω = ∇ × u by central differences of cell-centred velocity.
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const glm::vec3 xp = centre(i + 1, j, k), xm = centre(i - 1, j, k);
        const glm::vec3 yp = centre(i, j + 1, k), ym = centre(i, j - 1, k);
        const glm::vec3 zp = centre(i, j, k + 1), zm = centre(i, j, k - 1);
        omega(i, j, k) = inv2h * glm::vec3((yp.z - ym.z) - (zp.y - zm.y),
                                           (zp.x - zm.x) - (xp.z - xm.z),
                                           (xp.y - xm.y) - (yp.x - ym.x));
      }
  });
  // f = ε Δx (N × ω), N the normalised gradient of |ω|.
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        if (types(i, j, k) != kFluid) {
          force(i, j, k) = glm::vec3(0.f);
          continue;
        }
        auto mag = [&](int a, int b, int c) {
          return glm::length(omega(glm::clamp(a, 0, n.x - 1), glm::clamp(b, 0, n.y - 1),
                                   glm::clamp(c, 0, n.z - 1)));
        };
        glm::vec3 grad(mag(i + 1, j, k) - mag(i - 1, j, k), mag(i, j + 1, k) - mag(i, j - 1, k),
                       mag(i, j, k + 1) - mag(i, j, k - 1));
        const float len = glm::length(grad);
        if (len < 1e-20f) {
          force(i, j, k) = glm::vec3(0.f);
          continue;
        }
        grad /= len;
        force(i, j, k) = epsilon * cellSize * glm::cross(grad, omega(i, j, k));
      }
  });
  forEachFluidFace(velocity, types, [&](float& u, int a, std::size_t lo, std::size_t hi) {
    u += dt * 0.5f * (force[lo][a] + force[hi][a]);
  });
}

}  // namespace plume
