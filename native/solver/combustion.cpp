#include "solver/combustion.h"

#include "core/parallel.h"
#include "solver/pressure.h"

#include <cmath>

namespace plume {

void burnFuel(ScalarGrid& fuel, ScalarGrid& soot, ScalarGrid& temperature, ScalarGrid& flame,
              ScalarGrid& divergence, const FlagGrid& types, const SmokeParams& p, float dt) {
  const glm::ivec3 n = fuel.size();
  const float burntShare = 1.f - std::exp(-p.burnRate * dt);  // exact solution of dF/dt = -rF
  const float phiPerBurnt = dt > 0.f ? p.expansion / dt : 0.f;
  parallelFor(0, n.z, [&](int k) {
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const std::size_t c = fuel.index(i, j, k);
        if (types[c] != kFluid || fuel[c] <= 0.f) {
          flame[c] = 0.f;
          divergence[c] = 0.f;
          continue;
        }
        const float f = fuel[c];
        const float burnt = f * burntShare;
        flame[c] = f < 1.f ? f : 1.f;
        fuel[c] = f - burnt;
        soot[c] += p.sootYield * burnt;
        temperature[c] += p.heatYield * burnt;
        divergence[c] = phiPerBurnt * burnt;
      }
  });
}

void coolAndConduct(ScalarGrid& temperature, ScalarGrid& scratch, const FlagGrid& types,
                    const SmokeParams& p, float dt) {
  const glm::ivec3 n = temperature.size();
  const float t0 = p.ambientTemperature;
  const float span = p.maxTemperature - t0;
  if (p.coolingRate > 0.f && span > 0.f) {
    parallelFor(0, n.z, [&](int k) {
      for (int j = 0; j < n.y; ++j)
        for (int i = 0; i < n.x; ++i) {
          float& t = temperature(i, j, k);
          if (t <= t0) continue;
          const float x = (t - t0) / span;
          const float cooled = t - dt * p.coolingRate * x * x * x * x;
          t = cooled > t0 ? cooled : t0;
        }
    });
  }
  if (p.conductivity <= 0.f) return;
  // Explicit diffusion is stable for κ dt / Δx² <= 1/6: split dt into enough sub-steps.
  const float h2 = p.cellSize * p.cellSize;
  const int steps = std::min(64, std::max(1, int(std::ceil(6.f * p.conductivity * dt / h2))));
  const float lambda = std::min(1.f / 6.f, p.conductivity * (dt / float(steps)) / h2);
  scratch.reshape(n);
  for (int s = 0; s < steps; ++s) {
    parallelFor(0, n.z, [&](int k) {
      for (int j = 0; j < n.y; ++j)
        for (int i = 0; i < n.x; ++i) {
          const float t = temperature(i, j, k);
          if (types(i, j, k) != kFluid) {
            scratch(i, j, k) = t;
            continue;
          }
          float sum = 0.f;
          const glm::ivec3 c(i, j, k);
          for (int a = 0; a < 3; ++a)
            for (int d = -1; d <= 1; d += 2) {
              glm::ivec3 q = c;
              q[a] += d;
              float tn;
              if (q[a] < 0 || q[a] >= n[a]) {
                const int side = 2 * a + (d > 0 ? 1 : 0);
                tn = p.boundaries[side] == Boundary::Open ? t0 : t;  // air or insulating wall
              } else {
                tn = types(q.x, q.y, q.z) == kFluid ? temperature(q.x, q.y, q.z) : t;
              }
              sum += tn - t;
            }
          scratch(i, j, k) = t + lambda * sum;
        }
    });
    std::swap(temperature.values(), scratch.values());
  }
}

}  // namespace plume
