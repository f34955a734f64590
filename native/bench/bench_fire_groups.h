#pragma once
/// \file bench_fire_groups.h
/// Fire-like pathline groups for the synthesis benchmarks ([Graph Fire Synthesis] §5.2).

#include "core/rng.h"
#include "flowgraph/pathline_group.h"

#include <cmath>
#include <vector>

namespace plume::bench {

/// `count` groups of |Ω| = particles, L = samples, Δt_n = nodeDt: seeds on a 1 m burner square at
/// the bottom of a 2 m box, rising at 0.5 to 2.5 m/s with a swirl, density and temperature fading
/// over the lifetime.
inline std::vector<PathlineGroup> fireGroups(int count, int particles, int samples, float nodeDt) {
  const PathlineLayout layout{particles, samples, nodeDt};
  std::vector<PathlineGroup> groups(static_cast<std::size_t>(count));
  Rng rng(9);
  for (int k = 0; k < count; ++k) {
    PathlineGroup& g = groups[std::size_t(k)];
    g.step = k;
    g.layout = layout;
    g.start.resize(std::size_t(particles));
    g.velocity.resize(layout.values());
    g.density.resize(layout.values());
    g.temperature.resize(layout.values());
    for (int p = 0; p < particles; ++p) {
      g.start[std::size_t(p)] = glm::vec3(0.5f + float(rng.uniform()), 0.5f + float(rng.uniform()), 0.05f);
      const float rise = 0.5f + 2.f * float(rng.uniform()), phase = 6.28f * float(rng.uniform());
      for (int s = 0; s < samples; ++s) {
        const float t = float(s) * nodeDt, life = 1.f - float(s) / float(samples);
        const std::size_t i = g.index(p, s);
        g.velocity[i] = glm::vec3(0.4f * std::cos(phase + 5.f * t), 0.4f * std::sin(phase + 5.f * t), rise);
        g.density[i] = life;
        g.temperature[i] = 4.f * life * life;
      }
    }
  }
  return groups;
}

}  // namespace plume::bench
