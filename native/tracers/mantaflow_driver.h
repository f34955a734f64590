#pragma once
/// \file mantaflow_driver.h
/// Streaklines driven by a baked Blender Mantaflow cache instead of the Plume solver
/// ([Smoke Surfaces] §3.2: the particles are "advected by the velocity field"; any velocity
/// field will do, so an artist's existing Mantaflow bake can drive them).
///
/// Time. The cache holds the fields at frame ends only. Over one frame of length T from frame
/// f's fields (A) to frame f+1's (B) the velocity is taken as linear in time,
/// u(t) = (1 - t/T) A + (t/T) B, and the frame is cut into n equal substeps with the largest
/// speed of A and B crossing at most `cfl` (default 1) cells per substep. Each substep is one
/// StreakTracer::step() (explicit midpoint rule, second order in time) with the blended fields
/// at its start and end, so the whole frame is second order in time, and exact for a field
/// uniform in space and linear in time. Emission follows the tracer's emission period in
/// substeps, as with the solver's own steps.
///
/// Space. Mantaflow's cells are not cubic in world space (the domain box is stretched over
/// base_res cells), so the tracer runs in the Mantaflow grid's index space (cell size 1) with
/// the velocity in cells per second; positions cross to world space only at addPointSources()
/// and snapshot(), through MantaflowGrid::indexToWorld (exact for every axis).

#include <array>
#include <vector>

#include "io/mantaflow_cache.h"
#include "tracers/streak_tracer.h"

namespace plume {

/// Settings of a Mantaflow-driven trace.
struct MantaflowTraceParams {
  StreakParams streak;  ///< emission period (in substeps) and interpolation
  float cfl = 1.f;      ///< most cells a particle may cross per substep
  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
};

/// Accepted CFL range and the most substeps one frame may take (a broken cache could ask for
/// millions).
constexpr float kMinTraceCfl = 0.05f;
constexpr float kMaxTraceCfl = 10.f;
constexpr int kMaxTraceSubsteps = 4096;

/// A StreakTracer fed with the frames of a Mantaflow cache (see the file comment).
class MantaflowTracer {
 public:
  /// `boundaries` (-x,+x,-y,+y,-z,+z): Mantaflow's border collisions (closed) or open sides.
  /// Throws std::invalid_argument for bad params or grid.
  MantaflowTracer(const MantaflowTraceParams& params, const MantaflowGrid& grid,
                  const std::array<Boundary, 6>& boundaries);

  const MantaflowGrid& grid() const { return mGrid; }
  const StreakTracer& tracer() const { return mTracer; }

  /// Still point sources at world positions (source ID = index); only before the first frame.
  /// Throws std::invalid_argument (sizes, non-finite values, positions outside the domain).
  int addPointSources(const std::vector<glm::vec3>& worldPositions, const std::vector<int>& groups);

  /// Substeps advanceFrame() takes for frames a -> b of length frameDt (seconds).
  int substeps(const MantaflowFrame& a, const MantaflowFrame& b, float frameDt) const;

  /// Advances the particles over one frame of length frameDt (seconds) from frame a's fields to
  /// frame b's (see the file comment); density is sampled from b. Returns the substeps taken,
  /// or 0 when cancel() was called (the tracer is then mid-frame and must be discarded).
  /// Throws std::invalid_argument on a bad frameDt or frames not on the grid, and
  /// std::runtime_error when the speed would need more than kMaxTraceSubsteps substeps.
  int advanceFrame(const MantaflowFrame& a, const MantaflowFrame& b, float frameDt);

  /// The streaklines now, positions in world space (§3.2, Figure 2).
  StreakFrame snapshot() const;

  /// Pauses or resumes emission (StreakTracer::setEmitting, Figure 10's gap in the streaklines).
  void setEmitting(bool emitting) { mTracer.setEmitting(emitting); }

  /// Thread-safe: a running advanceFrame() returns 0 before its next substep.
  void cancel() { mTracer.cancel(); }

 private:
  /// out = ((1 - t) a + t b) / cellSize per axis: blended face velocity in cells per second.
  void blend(const MantaflowFrame& a, const MantaflowFrame& b, float t, MacGrid3& out) const;

  MantaflowTraceParams mParams;
  MantaflowGrid mGrid;
  StreakTracer mTracer;
  MacGrid3 mStart, mEnd;  ///< blended velocities at a substep's start and end (reused)
};

}  // namespace plume
