#pragma once
/// \file back_trace.h
/// The characteristics of semi-Lagrangian advection (Stam 1999 §3.2): where each sample of a
/// grid was Δt ago (and, for BFECC and MacCormack, will be Δt later), as SamplePoints.

#include "core/mac_grid3.h"
#include "core/sample_points.h"
#include "solver/block_mask.h"
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

/// Traces every sample of a grid through a velocity field.
class BackTracer {
 public:
  /// Traces the samples of a grid of `size` whose sample (0,0,0) sits at `offset`, by
  /// `cells` = Δt/Δx, in the active blocks of `mask` (nullptr = everywhere), into `back`
  /// (positions in the grid's own index space) and, when `fore` is given, forward by the same
  /// Δt into `fore` (BFECC's and MacCormack's reverse step). Midpoint: p - Δt u(p - ½Δt u(p));
  /// Euler: p - Δt u(p). At a sample p each velocity component is the exact average of the 1,
  /// 2 or 4 faces around it (Mantaflow's getCentered / getAtMACX..Z): sampleVelocity(p) bit for
  /// bit, from tabulated taps instead of a split per sample.
  void trace(const MacGrid3& velocity, glm::ivec3 size, glm::vec3 offset, float cells,
             Trace order, const BlockMask* mask, SamplePoints& back, SamplePoints* fore);

 private:
  /// What the first velocity samples of a row (j, k) share, per component a: offsets of rows
  /// (j,k), (j+1,k), (j,k+1), (j+1,k+1) of its y/z taps, and their fractions.
  struct RowTaps {
    std::ptrdiff_t row[3][4];
    float ty[3], tz[3];
  };

  /// Sets up the traces of the samples of a grid (taps, velocity, Δt/Δx, order).
  void prepare(const MacGrid3& velocity, glm::ivec3 size, glm::vec3 offset, float cells,
               Trace order);
  RowTaps rowTaps(int j, int k) const;
  /// The traces of samples i0 .. i1-1 (at most 8) of row (j, k) of the prepared grid into
  /// points 0 .. i1-i0-1 of `back` (and `fore`).
  void traceRun(const RowTaps& row, int i0, int i1, int j, int k, PointSink& back,
                PointSink* fore) const;

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

   private:
    std::vector<Tap> mTaps[3][3];
  };

  Taps mTaps;
  const MacGrid3* mVelocity = nullptr;
  glm::ivec3 mSize{0};
  glm::vec3 mOffset{0.f};
  float mCells = 0.f;
  Trace mOrder = Trace::Midpoint;
  bool mAvx2 = false;  ///< hasAvx2(), asked once per trace
};

}  // namespace plume
