#pragma once
/// \file pathline_group.h
/// A node of the flow graph ([Graph Fire Synthesis] §4.2-4.3, eq. 7): the pathlines of the
/// particles seeded in the fuel-injection region Ω at node step k of one fire bake ("state"),
/// with velocity U_k, soot density R_k and temperature T_k sampled at L equally spaced times
/// over the lifetime [0, t_max].
///
/// Plume's solver adapts its substep to the CFL condition, so the paper's fixed "time step" is
/// here the node step Δt_n (a frame divided by nodes_per_frame): one group is seeded per node
/// step, pathlines are integrated with RK4 across the solver's substeps, and samples are taken
/// every Δt_n, so sample s of every group is at local time s Δt_n and L Δt_n = t_max.

#include <glm/glm.hpp>

#include <cstddef>
#include <vector>

namespace plume {

/// The shape shared by every group of one flow graph: |Ω| particles, L samples Δt_n apart.
struct PathlineLayout {
  int particles = 0;        ///< |Ω|: seeds per group (spacing Δx/2 in the source cells)
  int samples = 0;          ///< L: samples per pathline, at local times 0, Δt_n, ..., (L-1) Δt_n
  float sampleDt = 0.f;     ///< Δt_n in seconds
  std::size_t values() const { return std::size_t(particles) * std::size_t(samples); }
  bool operator==(const PathlineLayout& o) const {
    return particles == o.particles && samples == o.samples && sampleDt == o.sampleDt;
  }
};

/// One pathline group P_k with its sampled fields. Sample s of particle p is at index
/// p * samples + s. A particle that left the domain keeps its last position and samples
/// zero velocity, density and temperature from then on (it has dissipated for rendering).
struct PathlineGroup {
  int state = 0;  ///< which fire bake (state) of the graph
  int step = 0;   ///< k: node step of the state at which the group was seeded
  PathlineLayout layout;
  std::vector<glm::vec3> start;     ///< x_0 per particle (world, m)
  std::vector<glm::vec3> velocity;  ///< u(x, t_k, t) per sample (m/s)
  std::vector<float> density;       ///< R: soot density per sample
  std::vector<float> temperature;   ///< T per sample
  std::size_t index(int particle, int sample) const {
    return std::size_t(particle) * std::size_t(layout.samples) + std::size_t(sample);
  }
};

}  // namespace plume
