#pragma once
/// \file flames_scenes.h
/// The structural-flame set-ups of the paper's results ([Structural Flames] §7) shared by the
/// tests and the benchmark: the torch of Figure 1 (5 flames waved through the air) and the
/// dragon breath of Figure 5 (5 flames splitting into 80+).

#include "flames/flame_system.h"

#include <cmath>
#include <memory>

namespace plume::testing {

/// Five sources on a torch head (radius 4 cm) moving at `speed` m/s along +x, n = `points`,
/// buoyancy, diffusion, a little turbulence and (FlameParams' default) the Kolmogorov noise on
/// the control points (§7: "influenced by thermal buoyancy and Kolmogorov noise").
inline FlameSystem torchFlames(std::uint64_t seed, int points = 16, double speed = 1.5) {
  FlameParams p;
  p.points = points;
  p.heightPersistent = 0.08;
  p.heightIntermittent = 0.16;
  p.heightMax = 0.35;
  p.lifespanScale = 0.25;
  p.buoyancy = 0.5;
  p.diffusion = 2e-4;
  FlameSystem system(p, seed);
  for (int s = 0; s < 5; ++s) {
    FlameSource src;
    const double a = 6.283185307179586 * s / 5.0;
    src.position = glm::dvec3(0.04 * std::cos(a), 0.04 * std::sin(a), 1.0);
    src.radius = 0.02;
    src.velocity = glm::dvec3(speed, 0.0, 0.0);
    system.addSource(src);
  }
  system.wind().add(std::make_shared<TurbulenceWind>(/*strength=*/0.3, /*size=*/0.2, /*flow=*/1.0, seed));
  return system;
}

/// Five sources at a dragon's mouth breathing along +x: the breath is a 6 m/s jet (a uniform
/// wind) with turbulence; pieces (A = 1 s) break off at f = 10 Hz or at H_max and split again,
/// about 100 flames alive after the first second.
inline FlameSystem dragonFlames(std::uint64_t seed, int points = 16) {
  FlameParams p;
  p.points = points;
  p.heightPersistent = 0.1;
  p.heightIntermittent = 0.25;
  p.heightMax = 0.6;
  p.lifespanScale = 1.0;
  p.breakawayFrequency = 10.0;
  p.buoyancy = 0.3;
  p.diffusion = 1e-3;
  FlameSystem system(p, seed);
  for (int s = 0; s < 5; ++s) {
    FlameSource src;
    src.position = glm::dvec3(0.0, 0.03 * (s - 2), 1.5 + 0.01 * (s % 2));
    src.normal = glm::dvec3(1.0, 0.0, 0.0);
    src.radius = 0.03;
    system.addSource(src);
  }
  system.wind().add(std::make_shared<UniformWind>(glm::dvec3(6.0, 0.0, 0.0)));
  system.wind().add(std::make_shared<TurbulenceWind>(/*strength=*/0.5, /*size=*/0.5, /*flow=*/2.0, seed));
  return system;
}

}  // namespace plume::testing
