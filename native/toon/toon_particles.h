#pragma once
/// \file toon_particles.h
/// Cartoon-smoke particles driven frame by frame by a baked cache (cartoon_smoke.txt §2.1-2.3).
///
/// One frame (advanceFrame) is a list of named stages:
///   1. advect   - every particle through the frame with the velocity linear in time between the
///                 frame's start fields A and end fields B, in n equal substeps with the largest
///                 face speed of A and B crossing at most `cfl` cells per substep; Euler (§2.1)
///                 or explicit midpoint per substep;
///   2. sample   - velocity, density and temperature from B at the new position, trilinearly
///                 (§2.1 "linearly interpolated from the simulation grid"); a particle outside
///                 the domain box reads density 0;
///   3. resize   - the target size follows the density ramp (§2.3), 0 below ρ_death; the size
///                 moves toward it by at most maxSizeStep() per frame, and a particle below
///                 ρ_death is removed only once its size is 0 (never pops);
///   4. emit     - emissionCount particles at the sources, in turn over cells then points;
///   5. birth    - every cell whose density in B exceeds ρ_birth and that holds no particle gets
///                 one at a random position in it (§2.2: "new particles should be added in areas of
///                 sufficient density").
/// New particles start at size 0 and grow by the same bounded step. Emission then birth stop
/// when maxCount particles exist, in their fixed order (entries in turn; cells in index order).
/// Every random position comes from Rng(seed, stream of (frame, stage, cell or emission index)),
/// and particles are advected and sampled independently, so the result is bit-identical at any
/// thread count. Ids are given in creation order and never reused, so Blender can follow a
/// particle from frame to frame.

#include "toon/toon_fields.h"
#include "toon/toon_params.h"

#include <cstdint>
#include <vector>

namespace plume {

/// Every particle of a toon frame (structure of arrays, one entry per particle, ids ascending)
/// and the counters that make the next frame deterministic. A toon file (io/toon_file.h) holds
/// one, so a build can resume from any written frame.
struct ToonParticleState {
  std::vector<std::uint64_t> ids;
  std::vector<glm::vec3> positions;   ///< world space, metres
  std::vector<glm::vec3> velocities;  ///< m/s, sampled at the position (§2.1)
  std::vector<float> density;
  std::vector<float> temperature;
  std::vector<float> size;        ///< stencil diameter now, metres
  std::vector<float> targetSize;  ///< what the size moves toward (§2.3 ramp, 0 when dying)
  std::vector<float> color;       ///< colour ramp parameter in [0, 1] (§2.3)
  std::vector<std::int32_t> age;  ///< frames since birth
  std::uint64_t nextId = 0;       ///< id of the next particle created
  std::int64_t frame = 0;         ///< frames advanced so far

  std::size_t count() const { return ids.size(); }
  /// Throws std::invalid_argument when the arrays differ in length, ids are not ascending and
  /// below nextId, or a value is not finite or negative where it must not be.
  void validate() const;
  /// Resizes every array to n entries.
  void resize(std::size_t n);
};

/// The particles and their per-frame evolution (see the file comment).
class ToonParticles {
 public:
  /// Throws std::invalid_argument for bad params (ToonParams::validate) or grid.
  ToonParticles(const ToonParams& params, const GridFrame& grid);

  const ToonParams& params() const { return mParams; }
  const GridFrame& grid() const { return mGrid; }
  const ToonParticleState& state() const { return mState; }
  /// Replaces the particles and counters (resume from a toon file). Throws
  /// std::invalid_argument (ToonParticleState::validate or more than maxCount particles),
  /// leaving the particles unchanged.
  void setState(ToonParticleState state);
  std::size_t count() const { return mState.count(); }

  /// Substeps advanceFrame() takes over a frame of length dt (seconds) from `before` to `after`.
  /// Throws std::invalid_argument on a bad dt or fields off the grid, std::runtime_error when
  /// the speed would need more than kMaxToonSubsteps substeps.
  int substeps(const ToonFields& before, const ToonFields& after, float dt) const;

  /// Advances the particles over one frame of length dt (seconds) from fields `before` (frame
  /// start) to `after` (frame end) and emits at `sources` (see the file comment). Returns the
  /// substeps taken. Throws as substeps(), and std::invalid_argument for sources off the grid;
  /// the particles are unchanged when it throws.
  int advanceFrame(const ToonFields& before, const ToonFields& after, float dt,
                   const ToonSources& sources);

 private:
  glm::vec3 toCell(glm::vec3 world) const {
    return (world - mGrid.origin) * mInvCellSize - glm::vec3(0.5f);
  }
  bool insideBox(glm::vec3 x) const {
    return x.x >= mGrid.origin.x && x.y >= mGrid.origin.y && x.z >= mGrid.origin.z && x.x <= mHi.x &&
           x.y <= mHi.y && x.z <= mHi.z;
  }
  /// mOrder = the particles [0, count) sorted by grid row (j, k) of their position, stable: the
  /// order in which advect() and sample() visit them, so that consecutive particles read the same
  /// few rows of every field (the results do not depend on the order).
  void sortByRow();
  void advect(const ToonFields& a, const ToonFields& b, float dt, int substeps);
  /// Stage 2 and the ramps for particles [first, count): velocity, density, temperature from
  /// `b`; target size and colour. When `resize` (the particles of the frame start, visited in
  /// mOrder, which must be current), the size moves toward the target.
  void sample(const ToonFields& b, std::size_t first, bool resize);
  void removeDead();
  void emit(const ToonSources& sources);
  void birth(const ToonFields& b);
  /// Appends a particle of size 0 at `position` (sampled later).
  void append(glm::vec3 position);

  ToonParams mParams;
  GridFrame mGrid;
  float mInvCellSize;
  glm::vec3 mHi;  ///< far corner of the domain box (mGrid.origin is the near one)
  ToonParticleState mState;
  std::vector<std::uint8_t> mOccupied;  ///< per cell, scratch of birth()
  std::vector<std::uint32_t> mOrder, mRowStart;  ///< scratch of sortByRow()
};

}  // namespace plume
