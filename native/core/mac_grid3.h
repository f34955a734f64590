#pragma once
/// \file mac_grid3.h
/// Staggered (MAC) velocity grid: u on x-faces, v on y-faces, w on z-faces (Harlow & Welch;
/// the layout of [Smoke Surfaces] §3.1 and Stam 1999).

#include "core/grid3.h"

namespace plume {

/// Face velocities of an nx*ny*nz cell grid. u(i,j,k) lives on the face between cells (i-1,j,k)
/// and (i,j,k), so u has (nx+1)*ny*nz samples; likewise v and w.
class MacGrid3 {
 public:
  MacGrid3() = default;
  explicit MacGrid3(glm::ivec3 cells) { resize(cells); }

  void resize(glm::ivec3 cells) {
    mCells = cells;
    mU.resize(cells + glm::ivec3(1, 0, 0));
    mV.resize(cells + glm::ivec3(0, 1, 0));
    mW.resize(cells + glm::ivec3(0, 0, 1));
  }
  void fill(float value) {
    mU.fill(value);
    mV.fill(value);
    mW.fill(value);
  }
  glm::ivec3 cells() const { return mCells; }

  ScalarGrid& u() { return mU; }
  ScalarGrid& v() { return mV; }
  ScalarGrid& w() { return mW; }
  const ScalarGrid& u() const { return mU; }
  const ScalarGrid& v() const { return mV; }
  const ScalarGrid& w() const { return mW; }
  /// Component a (0=u, 1=v, 2=w).
  ScalarGrid& component(int a) { return a == 0 ? mU : (a == 1 ? mV : mW); }
  const ScalarGrid& component(int a) const { return a == 0 ? mU : (a == 1 ? mV : mW); }

  /// Velocity at the centre of cell (i,j,k): the mean of its two faces on each axis.
  glm::vec3 cellCenter(int i, int j, int k) const {
    return {0.5f * (mU(i, j, k) + mU(i + 1, j, k)), 0.5f * (mV(i, j, k) + mV(i, j + 1, k)),
            0.5f * (mW(i, j, k) + mW(i, j, k + 1))};
  }

 private:
  glm::ivec3 mCells{0};
  ScalarGrid mU, mV, mW;
};

}  // namespace plume
