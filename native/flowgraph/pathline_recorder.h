#pragma once
/// \file pathline_recorder.h
/// Records the pathline groups of a fire bake ([Graph Fire Synthesis] §4.2-4.3, eqs. 6-7)
/// while SmokeSolver::advanceFrame() runs: a StepObserver that follows every substep.
///
/// Timeline. Node steps are Δt_n = frame_dt / nodes_per_frame apart (pathline_group.h); node n
/// is at n Δt_n after the first step the recorder observes. At node n the recorder
///   1. samples every live group at its particles (velocity, density, temperature: sample
///      s = n - k of the group seeded at node k), hands each group that now holds L samples to
///      the sink and recycles its buffers;
///   2. seeds group n: |Ω| particles at the seeds (spacing Δx/2 in the fuel-injection cells),
///      and takes its sample 0.
/// Between node times every live particle moves by RK4 (eq. 6, pathline_integrator.h) through
/// the velocity linearly interpolated in time between the substep's start and end fields: the
/// start field is copied in beforeStep() (the solver keeps only the newest). A node time inside
/// a substep (nodes_per_frame > 1) splits the substep there; its density and temperature are
/// interpolated in time too, from copies made in beforeStep(). After F frames the bake has
/// produced F nodes_per_frame - L + 2 complete groups (the last L - 2 seeded are still young).
///
/// Density is what Plume renders as density: smoke density plus soot (the `density` grid of the
/// frame VDB, io/vdb_frame.h). Particles leave the domain through open sides only (a closed side
/// holds them on it, like the streak tracer); one that left keeps its last position inside and
/// samples zero from then on (pathline_group.h).
///
/// Cost: one RK4 pathline step (4 time-blended trilinear velocity samples) per live particle
/// per substep, at most kMaxRk4Steps when a particle crosses several cells, plus 3 samples per
/// particle at each node time; live particles = |Ω| L. Parallel over particles, deterministic.

#include "core/grid3.h"
#include "core/mac_grid3.h"
#include "flowgraph/pathline_group.h"
#include "solver/emitters.h"
#include "solver/smoke_params.h"
#include "solver/smoke_solver.h"

#include <array>
#include <atomic>
#include <functional>
#include <vector>

namespace plume {

/// Settings of the pathline sampling (§4.2).
struct PathlineParams {
  int nodesPerFrame = 2;  ///< node steps per frame: Δt_n = frame_dt / nodes_per_frame
  float lifetime = 1.f;   ///< t_max in seconds (§4.3: long enough for the particles to dissipate)
  /// Also hand the integrated position of every sample to the sink (tests compare them with
  /// synthesized particles); off in bakes.
  bool recordPositions = false;
  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
  /// L = round(lifetime / Δt_n) for a frame of `frameDt` seconds.
  int samples(float frameDt) const;
};

/// Largest accepted nodes per frame and samples per pathline.
constexpr int kMaxNodesPerFrame = 64;
constexpr int kMaxPathlineSampleCount = 100000;

/// Receives each completed group once, in node order. `positions` holds the integrated position
/// of every sample (index group.index(p, s)) when PathlineParams::recordPositions, else is empty.
/// Called on the solver's thread; the references are valid during the call only.
using PathlineSink =
    std::function<void(const PathlineGroup& group, const std::vector<glm::vec3>& positions)>;

/// Ω (eq. 7): 8 seeds per cell at spacing Δx/2, (i + 1/4 or 3/4, ...) Δx from the origin, in
/// ascending cell order (duplicates removed), x fastest within a cell. Throws
/// std::invalid_argument when `cells` is empty or holds an index outside the grid.
std::vector<glm::vec3> pathlineSeeds(const CellSet& cells, glm::ivec3 resolution, float cellSize,
                                     glm::vec3 origin);

/// The recorder (see the file comment). Attach with solver.advanceFrame(&recorder); false
/// from it (solver or recorder cancelled) leaves both mid-frame, to be discarded.
class PathlineRecorder final : public StepObserver {
 public:
  /// `fuelCells`: the cells where fuel is injected (Ω is seeded in them). Throws
  /// std::invalid_argument on bad settings or cells.
  PathlineRecorder(const PathlineParams& params, const SmokeParams& smoke, const CellSet& fuelCells,
                   PathlineSink sink);

  const PathlineParams& params() const { return mParams; }
  /// |Ω|, L and Δt_n of every group this recorder produces.
  const PathlineLayout& layout() const { return mLayout; }
  /// Ω, world positions.
  const std::vector<glm::vec3>& seeds() const { return mSeeds; }

  void beforeStep(const SmokeSolver& solver) override;
  void afterStep(const SmokeSolver& solver, float dt) override;
  bool cancelRequested() override { return mCancel.exchange(false); }
  /// Thread-safe: the running advanceFrame() returns false before its next step.
  void cancel() { mCancel.store(true); }

  /// Groups seeded so far (= the next node index) and handed to the sink so far.
  int groupsSeeded() const { return mSeeded; }
  int groupsCompleted() const { return mCompleted; }

 private:
  struct Live {
    PathlineGroup group;
    std::vector<glm::vec3> position;   ///< now, per particle
    std::vector<std::uint8_t> left;    ///< 1 once the particle has left through an open side
    std::vector<glm::vec3> trail;      ///< position per sample (recordPositions only)
    int taken = 0;                     ///< samples taken so far
  };
  /// The fields of one substep the samples read (θ in [0, 1] blends start and end).
  struct Fields;

  void checkSolver(const SmokeSolver& solver) const;
  void moveLive(const Fields& f, float thetaA, float thetaB, float dt);
  void nodeTime(const Fields& f, float theta);
  void seed();
  int liveCount() const { return mSeeded - mCompleted; }
  Live& slot(int node) { return mLive[std::size_t(node % mLayout.samples)]; }

  PathlineParams mParams;
  PathlineLayout mLayout;
  glm::ivec3 mResolution;
  float mCellSize, mFrameDt;
  glm::vec3 mOrigin, mLo, mHi;
  std::array<Boundary, 6> mBoundaries;
  std::vector<glm::vec3> mSeeds;
  PathlineSink mSink;
  std::vector<Live> mLive;  ///< ring of L slots: group k lives in slot k mod L
  MacGrid3 mVelocityStart;  ///< the solver's velocity at the start of the running substep
  ScalarGrid mDensityStart, mTemperatureStart;  ///< same, density + soot and T (mid-substep nodes)
  int mSeeded = 0, mCompleted = 0;
  int mFrame = -1, mSubstep = 0;  ///< the solver frame in progress and its substeps done
  std::atomic<bool> mCancel{false};
};

}  // namespace plume
