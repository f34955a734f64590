#pragma once
/// \file flowgraph_groups.h
/// Synthetic pathline groups and cost matrices for the flow-graph tests and benchmark
/// ([Graph Fire Synthesis] §4.2-4.3): each state's groups oscillate with a state-specific
/// period, so that nodes a period apart are alike (the recurrences transitions are made of).

#include "core/parallel.h"
#include "core/rng.h"
#include "flowgraph/cost_matrix.h"
#include "flowgraph/pathline_group.h"

#include <cmath>
#include <utility>
#include <vector>

namespace plume::testing {

/// Group `index` of a synthetic graph: node `step` of state `state`, |Ω| = particles, L = samples,
/// Δt_n = 1/48 s: velocity, density and temperature = a per-state base field ×
/// (1 + 0.3 sin(2π k / period_s)) plus uniform noise of ±noise, from Rng(seed, index) (so groups
/// may be made in any order, in parallel or one at a time).
inline void oscillatingGroup(int state, int step, int index, int particles, int samples, std::uint64_t seed,
                             float noise, PathlineGroup& g) {
  g.state = state;
  g.step = step;
  g.layout = {particles, samples, 1.f / 48.f};
  Rng rng(seed, std::uint64_t(index));
  const double period = 23.0 + 7.0 * g.state;
  const float wave = 1.f + 0.3f * float(std::sin(6.283185307179586 * g.step / period));
  const float strength = 1.f + 0.5f * float(g.state);
  g.start.resize(std::size_t(particles));
  g.velocity.resize(g.layout.values());
  g.density.resize(g.layout.values());
  g.temperature.resize(g.layout.values());
  auto jitter = [&] { return noise * float(rng.uniform(-1.0, 1.0)); };
  for (int p = 0; p < particles; ++p) {
    g.start[std::size_t(p)] = glm::vec3(0.01f * float(p % 17), 0.01f * float(p / 17), 0.f);
    for (int q = 0; q < samples; ++q) {
      const std::size_t i = g.index(p, q);
      const float fade = 1.f - float(q) / float(samples);  // particles dissipate over the lifetime
      g.velocity[i] = glm::vec3(0.2f * wave * float((p + q) % 5 - 2), 0.1f * float(p % 3), strength * wave * fade) +
                      glm::vec3(jitter(), jitter(), jitter());
      g.density[i] = 0.5f * wave * fade + jitter();
      g.temperature[i] = 3.f * strength * wave * fade * fade + jitter();
    }
  }
}

/// Groups of `counts[s]` nodes per state s (see oscillatingGroup()), made in parallel.
inline std::vector<PathlineGroup> oscillatingGroups(const std::vector<int>& counts, int particles, int samples,
                                                    std::uint64_t seed, float noise = 0.05f) {
  std::vector<std::pair<int, int>> nodes;  // (state, step)
  for (std::size_t s = 0; s < counts.size(); ++s)
    for (int k = 0; k < counts[s]; ++k) nodes.emplace_back(int(s), k);
  std::vector<PathlineGroup> groups(nodes.size());
  parallelFor(0, int(groups.size()), [&](int n) {
    const auto [state, step] = nodes[std::size_t(n)];
    oscillatingGroup(state, step, n, particles, samples, seed, noise, groups[std::size_t(n)]);
  });
  return groups;
}

/// Pointers to the groups, the form computeCostMatrix() takes.
inline std::vector<const PathlineGroup*> pointers(const std::vector<PathlineGroup>& groups) {
  std::vector<const PathlineGroup*> p;
  for (const PathlineGroup& g : groups) p.push_back(&g);
  return p;
}

/// A symmetric N×N cost matrix with zero diagonal: |sin| waves of node distance in time (per
/// state period) plus uniform noise in [0, 0.5), from Rng(seed).
inline CostMatrix randomCosts(int n, std::uint64_t seed) {
  CostMatrix c(n);
  Rng rng(seed);
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      c.set(i, j, std::fabs(std::sin(0.13 * (j - i))) + 0.5 * rng.uniform());
  return c;
}

}  // namespace plume::testing
