#pragma once
/// \file advection.h
/// Semi-Lagrangian advection (Stam 1999), BFECC (Kim, Liu, Llamas & Rossignac 2005) and
/// MacCormack (Selle, Fedkiw, Kim, Liu & Rossignac 2008), the last two with a clamp limiter, for
/// cell-centred scalars and the staggered velocity components.
///
/// Speed: back-traces are computed once per grid layout and shared by every field on it (density,
/// temperature, fuel and soot share one trace), and scalar fields skip the blocks of cells that
/// are far from any smoke (their value stays the background value exactly).

#include "core/grid3.h"
#include "core/mac_grid3.h"
#include "core/sampling.h"
#include "solver/smoke_params.h"

#include <vector>

namespace plume {

/// Where sample (0,0,0) of a grid sits, in cell coordinates: cells at 0, u-faces at (-½,0,0)...
constexpr glm::vec3 kCellOffset{0.f, 0.f, 0.f};
constexpr glm::vec3 kFaceOffsetU{-0.5f, 0.f, 0.f};
constexpr glm::vec3 kFaceOffsetV{0.f, -0.5f, 0.f};
constexpr glm::vec3 kFaceOffsetW{0.f, 0.f, -0.5f};

/// Back-traced position of p (cell coordinates) after `cells` = dt/Δx seconds-per-metre through
/// the velocity field: explicit midpoint rule (RK2), second order in time.
glm::vec3 traceBack(const MacGrid3& velocity, glm::vec3 p, float cells);

/// Blocks of 8³ samples that may hold something other than a field's background value after
/// advection: blocks holding such a value, dilated by two blocks (16 cells).
class BlockMask {
 public:
  static constexpr int kBlock = 8;
  static constexpr int kDilation = 2;  ///< blocks; covers 2 × (trace + stencil) of BFECC

  /// Marks the blocks of `field` with a value != background, then dilates.
  void build(const ScalarGrid& field, float background);
  /// Union with another mask of the same grid.
  void merge(const BlockMask& other);
  /// Marks everything active.
  void setAll(glm::ivec3 size);
  bool active(int bi, int bj, int bk) const {
    return mActive[std::size_t(bi) + std::size_t(mBlocks.x) * (std::size_t(bj) + std::size_t(mBlocks.y) * std::size_t(bk))] != 0;
  }
  glm::ivec3 blocks() const { return mBlocks; }
  /// Share of active blocks, in [0, 1].
  float fill() const;

 private:
  glm::ivec3 mBlocks{0};
  std::vector<std::uint8_t> mActive, mRaw;
};

/// Carries grids through a velocity field. Owns the traces and scratch BFECC needs, sized once.
///
/// Use: trace() for a layout, then advect() every field of that layout.
class Advector {
 public:
  /// Reserves traces and scratch for grids of up to `count` samples (no allocation afterwards).
  void reserve(std::size_t count);

  /// Traces every sample of a grid of `size` whose sample (0,0,0) sits at `offset`: back by Δt
  /// (and forth by Δt for BFECC) through `velocity`, only in the active blocks of `mask`
  /// (nullptr = everywhere).
  void trace(const MacGrid3& velocity, glm::ivec3 size, glm::vec3 offset, float dt, float cellSize,
             Advection scheme, const BlockMask* mask);

  /// dst = src advected with the last trace(). With BFECC: φ̂ = A(φ), φ̄ = A⁻¹(φ̂),
  /// result = A(φ + ½(φ - φ̄)) clamped to the range of φ around the back-traced point.
  /// With MacCormack: result = φ̂ + ½(φ - φ̄), clamped the same way (two passes, not three).
  /// Outside the active blocks of `mask` dst is `background`. dst must not alias src.
  void advect(const ScalarGrid& src, ScalarGrid& dst, Interpolation interpolation,
              const BlockMask* mask, float background);

 private:
  /// The trilinear taps of each velocity component at the samples of a traced grid, per axis:
  /// sample m of the grid reads component a along axis d at index i and i+1 with fraction t, as
  /// sampleLinear() would (t is 0, ½ or, on the last sample, 1).
  class Taps {
   public:
    struct Tap {
      int i;
      float t;
    };
    void build(const MacGrid3& velocity, glm::ivec3 size, glm::vec3 offset);
    Tap at(int component, int axis, int m) const { return mTaps[component][axis][std::size_t(m)]; }
    /// sampleLinear()'s lerps, x then y then z, skipping those with fraction 0 (which return
    /// their first operand unchanged): q points at x-tap i of row 0; row[] holds the offsets of
    /// rows (j,k), (j+1,k), (j,k+1), (j+1,k+1).
    static float lerp3(const float* q, const std::ptrdiff_t* row, float tx, float ty, float tz) {
      auto lx = [&](std::ptrdiff_t r) {
        return tx != 0.f ? q[r] + tx * (q[r + 1] - q[r]) : q[r];
      };
      auto ly = [&](std::ptrdiff_t r0, std::ptrdiff_t r1) {
        const float a = lx(r0);
        return ty != 0.f ? a + ty * (lx(r1) - a) : a;
      };
      const float c0 = ly(row[0], row[1]);
      return tz != 0.f ? c0 + tz * (ly(row[2], row[3]) - c0) : c0;
    }

   private:
    std::vector<Tap> mTaps[3][3];
  };

  ScalarGrid mForward, mBackward;
  Taps mTaps;
  std::vector<glm::vec3> mBack, mFore;  ///< traced positions in the grid's index space
  Advection mScheme = Advection::SemiLagrangian;
};

}  // namespace plume
