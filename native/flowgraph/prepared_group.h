#pragma once
/// \file prepared_group.h
/// A pathline group in the form the synthesis emits ([Graph Fire Synthesis] §5.2, eq. 13):
/// the pathline part of every particle's position at each of its L samples, summed once by the
/// trapezoid rule, with density and temperature, sample-major ([age][particle]) so that the
/// steps and gather() stream. It does not depend on u_ext, so it is immutable once made and
/// shared (std::shared_ptr<const PreparedGroup>) by every live slot of the synthesizer that
/// emitted its node and by the cache of prepared groups: a revisited node costs no copy.

#include "flowgraph/pathline_group.h"

#include <glm/glm.hpp>

#include <cstddef>
#include <memory>
#include <vector>

namespace plume {

/// Eq. 13 without u_ext, per sample of every particle of one node (see the file comment).
struct PreparedGroup {
  int state = 0;  ///< the group's state (fire bake)
  int step = 0;   ///< the group's node step k in its state
  PathlineLayout layout;
  std::vector<glm::vec3> path;              ///< [age][particle]: x_0 + Σ trapezoids up to age
  std::vector<float> density, temperature;  ///< [age][particle]: the samples of that age
  std::vector<glm::vec3> velocity;          ///< [age][particle]: u sample of that age (motion blur)
  /// Heap bytes held (what a cache of prepared groups budgets).
  std::size_t bytes() const;
};

/// Fills `out` from `group` (buffers reused): for particle p and age a,
///   path[a][p] = x_0 + Σ_{b<a} Δt_n (u_b + u_{b+1}) / 2      (eq. 13, trapezoid rule)
/// and the density and temperature samples of age a. Parallel over particles in fixed chunks
/// (each particle's sum runs in sample order): bit-identical at any thread count. The group's
/// arrays must match its layout (the caller checks).
void prepareGroup(const PathlineGroup& group, PreparedGroup& out);

/// Bytes a prepared group of `layout` holds: |Ω| L (12 + 4 + 4 + 12).
std::size_t preparedGroupBytes(const PathlineLayout& layout);

}  // namespace plume
