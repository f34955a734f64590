#pragma once
/// \file streak_tracer.h
/// Streaklines ([Smoke Surfaces] §3.2): massless particles emitted from point sources every
/// emission period and carried by the solver's time-varying velocity, second order in time.
///
/// Timeline. Emission happens at the instants t = s·Δt with s = 0, P, 2P, … (P = emission
/// period, s counts the steps this tracer has seen): the particle of instant 0 is emitted when the
/// point sources are added, the others at the end of the step that reaches their instant. After S
/// steps every source therefore holds floor(S / P) + 1 particles, the youngest at the source,
/// unless emission was paused.
///
/// Pausing (Figure 10: "particle emission was turned off" for frames 101-160). setEmitting(false)
/// makes the emission instants reached while paused add no particle row, so the particles born
/// on either side of the pause lie far apart along every streakline (the gap in the sheets);
/// particles already emitted keep moving. The switch is per tracer, not per point source: h(α,β)
/// (§3.3) pairs particles by index and the control nets are fixed, so every streakline keeps the
/// same particle count. A caller with several sources pauses only when none of them emits (the
/// add-on's Emit Particles switch); sources whose smoke is off but whose particles keep coming
/// carry the field's (zero) density. The first particle of each source, emitted when it is added,
/// is never skipped.
///
/// Boundaries. A particle pushed through a closed side is clamped onto it and keeps moving; one
/// carried through an open side is marked `outside`, its density becomes 0 (no smoke is
/// simulated there) and it goes on in a straight line with the velocity it left with, so the
/// streakline stays evenly spaced. It is kept so that every streakline of a bake has the same
/// particle count, which the distance h(α,β) of §3.3 and the fixed control nets need.

#include "core/grid3.h"
#include "core/mac_grid3.h"
#include "core/sampling.h"
#include "solver/emitters.h"
#include "solver/smoke_params.h"
#include "tracers/streak_frame.h"

#include <array>
#include <atomic>
#include <vector>

namespace plume {

class SmokeSolver;

/// Settings of the streakline tracer (§3.2).
struct StreakParams {
  int emissionPeriod = 1;  ///< steps between two emissions; §3.2 shoots one every step
  /// How velocity and density are read between grid samples (§3.2: "the same interpolation").
  Interpolation interpolation = Interpolation::MonotonicCubic;
  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
};

/// Largest accepted emission period, in steps.
constexpr int kMaxEmissionPeriod = 100000;

/// A point source (§3.2): where its particles are born, its candidate group (§3.3) and the
/// velocity its particles leave it with (the source's velocity, zero for a still source).
struct PointSource {
  glm::vec3 position{0.f};
  int group = 0;
  glm::vec3 velocity{0.f};
};

/// Everything a StreakTracer accumulates while it runs (§3.2): its point sources and their
/// particles, emission-major (particle e of source s at e * sources.size() + s), with the density
/// sampled at each, the outside flag and exit velocity of particles that left through an open
/// side, the particle rows emitted, the steps seen and the pause switch (Figure 10). A checkpoint
/// (tracers/tracer_state_file.h) saves it so that a traced bake resumes bit for bit.
struct StreakTracerState {
  std::vector<PointSource> sources;
  std::vector<glm::vec3> positions;
  std::vector<float> density;
  std::vector<std::uint8_t> outside;     ///< 0 or 1
  std::vector<glm::vec3> exitVelocity;   ///< velocity a particle left the domain with
  /// Particle rows emitted: floor(steps / emission period) + 1 less the instants skipped while
  /// paused.
  int emissions = 1;
  long long steps = 0;
  /// Step count at which the youngest row was emitted (0: the row emitted with the sources); its
  /// particles are newborn during the step after it.
  long long lastEmissionStep = 0;
  bool emitting = true;  ///< false: emission instants add no row (Figure 10's gap)
  /// Throws std::invalid_argument when the counters disagree with each other and with
  /// `emissionPeriod`, the particle arrays do not hold sources × emissions entries, a flag is
  /// not 0/1 or a value is not finite.
  void validate(int emissionPeriod) const;
};

/// Emits and advects the particles of streaklines (§3.2). Independent of SmokeSolver: step()
/// takes the velocity at the start and end of a step and the density at the end; observeStep()
/// and advanceFrameWithTracers() (tracer_driver.h) feed it from a solver.
class StreakTracer {
 public:
  /// `grid` fixes the domain box and the index space of the fields; `boundaries` (-x,+x,-y,+y,-z,+z)
  /// say through which sides particles leave. Validates params (std::invalid_argument).
  StreakTracer(const StreakParams& params, const GridFrame& grid,
               const std::array<Boundary, 6>& boundaries);
  /// Same, on the domain and boundaries of a solver's settings.
  StreakTracer(const StreakParams& params, const SmokeParams& smoke);

  const StreakParams& params() const { return mParams; }
  const GridFrame& gridFrame() const { return mGrid; }
  /// Sides (-x, +x, -y, +y, -z, +z) through which particles leave.
  const std::array<Boundary, 6>& boundaries() const { return mBoundaries; }

  /// Sources, particles and counters, for checkpoints (tracers/tracer_state_file.h).
  const StreakTracerState& state() const { return mState; }
  /// Replaces sources, particles and counters with a saved state. Throws std::invalid_argument
  /// (StreakTracerState::validate, or a source outside the domain), leaving the tracer unchanged.
  void setState(StreakTracerState state);

  /// Adds point sources (source ID = index, in the order added) and emits their first particle.
  /// All arrays have one entry per source; `velocities` may be empty (still sources). Only
  /// allowed before the first step, so that every streakline keeps the same particle count.
  /// Throws std::invalid_argument on size mismatches, non-finite values or positions outside
  /// the domain. Returns the ID of the first added source.
  int addPointSources(const std::vector<glm::vec3>& positions, const std::vector<int>& groups,
                      const std::vector<glm::vec3>& velocities);
  const std::vector<PointSource>& pointSources() const { return mState.sources; }

  /// Advances every particle over one step of length dt (seconds) with the explicit midpoint
  /// rule, second order in time: k1 = u(x, t), x½ = x + ½Δt k1, u(x½, t + ½Δt) taken as the mean
  /// of the start- and end-of-step fields at x½, x' = x + Δt u(x½, t + ½Δt). A particle born at
  /// this step's start uses its source's velocity as k1 when that is non-zero (the velocity the
  /// solver writes into source cells). Then emits if due and samples density at every particle.
  /// `before`/`after` are the face velocities at the start/end of the step and `density` the
  /// density at the end, all on the grid given at construction.
  void step(const MacGrid3& before, const MacGrid3& after, const ScalarGrid& density, float dt);
  /// step() with the solver's current velocity and density as the end-of-step fields; call it
  /// right after solver.step(dt), with `velocityBefore` copied just before that call.
  void observeStep(const SmokeSolver& solver, const MacGrid3& velocityBefore, float dt);

  /// Pauses (false) or resumes (true) emission (Figure 10; see the file comment): while paused,
  /// the emission instants step() reaches add no particles; the others keep moving. Takes effect
  /// from the next emission instant.
  void setEmitting(bool emitting) { mState.emitting = emitting; }
  bool emitting() const { return mState.emitting; }

  /// Storage for the start-of-step velocity used by advanceFrameWithTracers (allocated once).
  MacGrid3& previousVelocity() { return mPrevious; }

  /// The streaklines now: per source, its particles in birth order (§3.2, Figure 2).
  StreakFrame snapshot() const;

  int sourceCount() const { return int(mState.sources.size()); }
  /// Particles per source (equal for all sources): floor(steps / period) + 1 if never paused.
  int particlesPerSource() const { return mState.emissions; }
  /// Steps seen so far.
  long long steps() const { return mState.steps; }

  /// Thread-safe: a running advanceFrameWithTracers() returns false before its next step.
  void cancel() { mCancel.store(true); }
  /// Returns whether cancel() was called since the last call, and clears the request.
  bool consumeCancel() { return mCancel.exchange(false); }

 private:
  void emit();
  glm::vec3 toCell(glm::vec3 world) const {
    return (world - mGrid.origin) * mInvCellSize - glm::vec3(0.5f);
  }
  void checkGrid(glm::ivec3 size, glm::ivec3 expected, const char* what) const;
  /// Throws std::invalid_argument unless source n is finite and inside the domain.
  void checkPointSource(std::size_t n, glm::vec3 position, glm::vec3 velocity) const;

  StreakParams mParams;
  GridFrame mGrid;
  std::array<Boundary, 6> mBoundaries;
  float mInvCellSize;
  glm::vec3 mLo, mHi;  ///< domain box, world space
  StreakTracerState mState;
  MacGrid3 mPrevious;
  std::atomic<bool> mCancel{false};
};

}  // namespace plume
