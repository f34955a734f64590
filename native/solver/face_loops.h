#pragma once
/// \file face_loops.h
/// The loop over the fluid faces of one velocity component that the force stages share.

#include "core/grid3.h"
#include "core/mac_grid3.h"
#include "core/parallel.h"
#include "solver/pressure.h"

#include <cstddef>

namespace plume {

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

}  // namespace plume
