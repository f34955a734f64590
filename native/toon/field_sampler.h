#pragma once
/// \file field_sampler.h
/// The trilinear samples a toon particle takes ([Cartoon Smoke] §2.1: "position, velocity, and
/// density are linearly interpolated from the simulation grid"), for a group of kToonLanes
/// particles at a time: the clamped split of each coordinate is computed once per position and
/// shared by every field (the cell-centred density and temperature, and the three staggered
/// velocity components). The interpolation runs on eight AVX2 lanes where the CPU has them (the
/// solver's corner gathers, core/linear_cells.h), else on two halves of four SSE lanes. Each
/// lane's value is the one sampleLinear / sampleVelocity (core/sampling.h) return, bit for bit:
/// same clamping, same operations in the same order, so the choice changes no result.
///
/// A NaN coordinate (only a broken velocity field makes one) reads as 0, the grid's first
/// sample, instead of an index far outside the grid; every other coordinate splits as
/// splitCoordinate() does.

#include "toon/toon_fields.h"

namespace plume {

/// Particles per group of the toon samplers.
constexpr int kToonLanes = 8;

/// kToonLanes 3-vectors as a structure of arrays: c[axis][lane].
struct ToonLanes3 {
  alignas(32) float c[3][kToonLanes];
};

/// The samples of a group of particles at cell coordinates (cell (i,j,k)'s centre at (i,j,k))
/// on a grid of `cells` cells.
class ToonFieldSampler {
 public:
  /// `wide`: use the eight-lane kernels where the CPU has AVX2 and the grids index in 31 bits
  /// (false: always four lanes; the values are the same).
  explicit ToonFieldSampler(glm::ivec3 cells, bool wide = true);
  /// Whether the eight-lane kernels run.
  bool wide() const { return mWide; }

  /// The face velocity at `cell`, linear in time between a (t = 0) and b (t = 1):
  /// (1 - t) v_a + t v_b, reading only a at t <= 0 and only b at t >= 1.
  void velocity(const MacGrid3& a, const MacGrid3& b, float t, const ToonLanes3& cell,
                ToonLanes3& v) const;
  /// Velocity, density and temperature (0 without a temperature grid) of f at `cell`.
  void fields(const ToonFields& f, const ToonLanes3& cell, ToonLanes3& v, float* density,
              float* temperature) const;

 private:
  glm::ivec3 mCells;
  bool mWide = false;
};

}  // namespace plume
