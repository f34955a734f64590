#pragma once
/// \file toon_particles.h
/// Cartoon-smoke particles driven frame by frame by a baked cache ([Cartoon Smoke] §2.1-2.3).
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
///                 sufficient density"), unless a particle lies closer than birthSpacing times the
///                 stencil size of the cell's density (birth_spacing.h; spacing 0: every such cell).
/// New particles start at size 0 and grow by the same bounded step. Emission then birth stop
/// when maxCount particles exist, in their fixed order (entries in turn; cells in index order).
/// Every random position comes from Rng(seed, stream of (frame, stage, cell or emission index)),
/// and particles are advected and sampled independently (stages 1-3 run as one pass per group of
/// particles, which also marks the cells that stage 5 finds occupied), so the result is
/// bit-identical at any thread count. Ids are given in creation order and never reused, so
/// Blender can follow a particle from frame to frame.

#include "toon/birth_spacing.h"
#include "toon/field_sampler.h"
#include "toon/toon_fields.h"
#include "toon/toon_params.h"

#include <cstdint>
#include <vector>

namespace plume {

/// Every particle of a toon frame (structure of arrays, one entry per particle, ids ascending)
/// and the counters that make the next frame deterministic. A toon file (toon/toon_file.h) holds
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
  bool insideBox(glm::vec3 x) const {
    return x.x >= mGrid.origin.x && x.y >= mGrid.origin.y && x.z >= mGrid.origin.z && x.x <= mHi.x &&
           x.y <= mHi.y && x.z <= mHi.z;
  }
  /// Index of the cell holding x (inside the box; the far faces count to the last cells).
  std::size_t cellIndex(glm::vec3 x) const {
    const glm::ivec3 n = mGrid.resolution;
    const glm::ivec3 c = glm::clamp(glm::ivec3(glm::floor((x - mGrid.origin) * mInvCellSize)),
                                    glm::ivec3(0), n - 1);
    return std::size_t(c.x) +
           std::size_t(n.x) * (std::size_t(c.y) + std::size_t(n.y) * std::size_t(c.z));
  }
  /// Positions of the particles index[0 .. kToonLanes-1].
  void gather(const std::size_t* index, ToonLanes3& x) const {
    for (int l = 0; l < kToonLanes; ++l)
      for (int a = 0; a < 3; ++a) x.c[a][l] = mState.positions[index[l]][a];
  }
  /// Cell coordinates (cell (i,j,k)'s centre at (i,j,k)) of every lane of world positions x.
  void toCells(const ToonLanes3& x, ToonLanes3& c) const {
    for (int a = 0; a < 3; ++a)
      for (int l = 0; l < kToonLanes; ++l)
        c.c[a][l] = (x.c[a][l] - mGrid.origin[a]) * mInvCellSize - 0.5f;
  }
  /// mOrder = the particles [0, count) sorted by grid row (j, k) of their position, stable: the
  /// order in which advectAndSample() visits them, so that consecutive particles read the same
  /// few rows of every field (the results do not depend on the order).
  void sortByRow();
  /// Stages 1-3 for every particle, in mOrder (which must be current): advect, then
  /// sampleGroup(resize) at the new position.
  void advectAndSample(const ToonFieldSampler& sampler, const ToonFields& a, const ToonFields& b,
                       float dt, int substeps);
  /// Stage 2 and the ramps for the particles index[0 .. lanes-1] at positions x (every lane
  /// finite, the padding ones too): velocity, density, temperature from `b`; target size and
  /// colour. When `resize` (the particles of the frame start), the size moves toward the target
  /// and the particles that survive removeDead() mark their cells in mOccupied for birth().
  void sampleGroup(const ToonFieldSampler& sampler, const ToonFields& b, const std::size_t* index,
                   int lanes, const ToonLanes3& x, bool resize);
  /// Removes the particles shrunk to size 0 below ρ_death, keeping the order of the others.
  void removeDead();
  void emit(const ToonSources& sources);
  /// Stage 5; mOccupied holds the survivors' cells, the particles from `emitted` on mark theirs.
  void birth(const ToonFields& b, std::size_t emitted);
  /// Appends a particle of size 0 at `position` (sampled later).
  void append(glm::vec3 position);

  ToonParams mParams;
  GridFrame mGrid;
  float mInvCellSize;
  glm::vec3 mHi;  ///< far corner of the domain box (mGrid.origin is the near one)
  ToonParticleState mState;
  std::vector<std::uint8_t> mOccupied, mWanted;  ///< per cell, scratch of a frame's birth()
  std::vector<std::size_t> mSlabOffset;          ///< per z slab, scratch of birth()
  BirthSpacingScratch mSpacing;                  ///< scratch of birth()'s spacing
  std::vector<std::uint32_t> mOrder, mRowStart, mRow;  ///< scratch of sortByRow()
};

}  // namespace plume
