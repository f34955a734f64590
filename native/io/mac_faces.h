#pragma once
/// \file mac_faces.h
/// Filling the faces of a MAC grid (mac_grid3.h) from the cells beside each face: how the VDB
/// readers turn stored velocities into face velocities.

#include "core/mac_grid3.h"
#include "core/parallel.h"

namespace plume {

/// Calls face(f, below, a) for every face f of every component a of a MAC grid, where
/// `below` is the cell under the face on axis a (f itself is the cell above), and stores the
/// result. Parallel over k; face() must only read.
template <typename Face>
void fillFaces(MacGrid3& mac, const Face& face) {
  for (int a = 0; a < 3; ++a) {
    ScalarGrid& c = mac.component(a);
    const glm::ivec3 s = c.size();
    glm::ivec3 step(0);
    step[a] = 1;
    parallelFor(0, s.z, [&](int k) {
      for (int j = 0; j < s.y; ++j)
        for (int i = 0; i < s.x; ++i) {
          const glm::ivec3 f(i, j, k);
          c(i, j, k) = face(f, f - step, a);
        }
    });
  }
}

/// Face velocities from cell-centred ones on a grid of n cells: the mean of the two cells beside
/// each face that hold a velocity (held(cell)), the one of them that does, or 0; value(cell, a)
/// is component a of a cell's velocity.
template <typename Held, typename Value>
void facesFromCentres(MacGrid3& mac, glm::ivec3 n, const Held& held, const Value& value) {
  fillFaces(mac, [&](glm::ivec3 above, glm::ivec3 below, int a) {
    float sum = 0.f;
    int count = 0;
    for (const glm::ivec3 p : {below, above})
      if (p[a] >= 0 && p[a] < n[a] && held(p)) {
        sum += value(p, a);
        ++count;
      }
    return count ? sum / float(count) : 0.f;
  });
}

}  // namespace plume
