#pragma once
/// \file smoke_solver.h
/// The fractional-step smoke/fire solver (Stam 1999) shared by all four pipelines:
/// sources, advection, forces, combustion, projection, as named stages of step().

#include "core/grid3.h"
#include "core/mac_grid3.h"
#include "solver/active_box.h"
#include "solver/advection.h"
#include "solver/emitters.h"
#include "solver/point_emitters.h"
#include "solver/pressure.h"
#include "solver/smoke_params.h"
#include "solver/source_noise.h"
#include "solver/turbulence.h"

#include <atomic>
#include <memory>
#include <string>
#include <vector>

namespace plume {

/// What a Source object puts into its cells each step.
struct SourceSettings {
  float density = 1.f;      ///< ρ set in source cells (the larger of this and what is there)
  float temperature = 1.f;  ///< T - T_amb set in source cells
  float fuel = 0.f;         ///< F set in source cells (combustion)
  glm::vec3 velocity{0.f};  ///< initial velocity, m/s ([Smoke Surfaces] §3.2)
  float motionFactor = 1.f; ///< share of the source object's own motion added to its velocity
  SourceNoise fuelNoise;    ///< flicker: patches of thinner fuel (source_noise.h)
  /// breakup: patches of thinner smoke and heat, for a source that burns no fuel (source_noise.h)
  SourceNoise smokeNoise;
  void validate() const;
};

/// No-slip obstacles drag the air to their own velocity; free-slip ones only stop the normal part.
enum class Slip { NoSlip, FreeSlip };

/// Figures of the last frame, for progress reports and tests.
struct StepStats {
  int substeps = 0;
  int pressureIterations = 0;     ///< summed over the frame's substeps
  float pressureResidual = 0.f;   ///< largest relative residual of the frame
  float maxSpeed = 0.f;           ///< m/s, at the end of the frame
};

class SmokeSolver;
class AdaptiveDomain;

/// Follows a simulation step by step, e.g. the streakline tracers of [Smoke Surfaces] §3.2,
/// whose particles move with the velocity of every step, not only of every frame.
class StepObserver {
 public:
  virtual ~StepObserver() = default;
  /// Before each step: the solver still holds the previous step's state.
  virtual void beforeStep(const SmokeSolver& solver) = 0;
  /// After each step of length dt.
  virtual void afterStep(const SmokeSolver& solver, float dt) = 0;
  /// Checked before each step, like SmokeSolver::cancel(): true stops the frame.
  virtual bool cancelRequested() { return false; }
};

/// One smoke/fire simulation. Holds all grids; allocation happens in the constructor and when
/// obstacles change, never inside step().
class SmokeSolver {
 public:
  /// Validates params (std::invalid_argument) and allocates the grids.
  explicit SmokeSolver(const SmokeParams& params);
  ~SmokeSolver();

  const SmokeParams& params() const { return mParams; }
  GridFrame gridFrame() const;

  // --- Emitters of the coming frame ---
  void clearEmitters();  ///< sources, obstacles and point emitters
  void addSource(const CellSet& cells, const SourceSettings& settings);
  void addObstacle(const CellSet& cells, Slip slip);
  /// Replaces the point emitters ([Structural Flames] §6.3 smoke) applied every step from now
  /// on; validates each (std::invalid_argument), radius at most the domain's longest side.
  void setPointEmitters(std::vector<PointEmitter> emitters);
  const std::vector<PointEmitter>& pointEmitters() const { return mPointEmitters; }
  /// Per-cell wind velocity (cell-centred), replacing the constant params().wind; empty = constant.
  void setWindField(const VectorGrid& wind);

  /// Advances one frame in one or more steps (params().substeps, more if CFL needs them).
  /// Returns false when cancel() was called; the state is then mid-frame and must be discarded.
  /// `observer`, when given, is called around every step.
  bool advanceFrame(StepObserver* observer = nullptr);
  /// One fractional step of length dt: the stages below, in order, on the whole domain (the
  /// adaptive domain applies in advanceFrame()).
  void step(float dt);
  /// Thread-safe: makes a running advanceFrame() return false after the current step.
  void cancel() { mCancel.store(true); }

  // --- Stages of step() (public so tests and benchmarks can run them one by one) ---
  void applySources(float dt);
  void advect(float dt);             ///< velocity and every scalar, chosen scheme
  void addForces(float dt);          ///< buoyancy, wind, vorticity confinement
  void burn(float dt);               ///< combustion eqs. 3-5 and the divergence φ of eq. 1
  void dissipate(float dt);          ///< density loss, ρ *= e^{-d dt}
  void project(float dt);            ///< make div u = φ with the boundary conditions

  // --- State ---
  int frame() const { return mFrame; }
  /// Sets the frame, and the clock of the sources' noise to its start.
  void setFrame(int frame) {
    mFrame = frame;
    mTime = double(frame) * double(mParams.frameDt);
  }
  const StepStats& lastStats() const { return mStats; }

  MacGrid3& velocity() { return mVelocity; }
  const MacGrid3& velocity() const { return mVelocity; }
  ScalarGrid& density() { return mDensity; }
  ScalarGrid& temperature() { return mTemperature; }
  ScalarGrid& fuel() { return mFuel; }
  ScalarGrid& soot() { return mSoot; }
  ScalarGrid& flame() { return mFlame; }
  ScalarGrid& pressure() { return mPressure; }
  const ScalarGrid& density() const { return mDensity; }
  const ScalarGrid& temperature() const { return mTemperature; }
  const ScalarGrid& fuel() const { return mFuel; }
  const ScalarGrid& soot() const { return mSoot; }
  const ScalarGrid& flame() const { return mFlame; }
  const ScalarGrid& pressure() const { return mPressure; }
  const FlagGrid& cellTypes() const { return mCellTypes; }

  /// The adaptive domain's box (adaptive_domain.h) of the last step, in cells; the whole domain
  /// when params().adaptiveDomain is off or before the first frame.
  ActiveBox activeBox() const;

  /// Largest |div u - φ| × Δx over fluid cells divided by the largest |u| (tests use it).
  float maxDivergence() const;
  /// Largest face speed, m/s.
  float maxSpeed() const;

 private:
  friend class AdaptiveDomain;  // adaptive_domain.h: runs the steps on the box around the smoke
  struct Source {
    CellSet cells;
    SourceSettings settings;
  };
  struct Obstacle {
    CellSet cells;
    Slip slip;
  };

  void rebuildCellTypes();
  void enforceBoundaryVelocities();
  void applyPressureGradient();
  float fluxSum(int i, int j, int k) const;
  void zeroSolidScalars();

  SmokeParams mParams;
  MacGrid3 mVelocity, mVelocityTmp, mVelocityTmp2;
  ScalarGrid mDensity, mTemperature, mFuel, mSoot, mFlame;
  ScalarGrid mScalarTmp[Advector::kMaxFields];  ///< advected scalars (burn: [0] is scratch)
  ScalarGrid mPressure, mRhs, mDivergenceTarget;
  VectorGrid mVorticity, mForce, mWindField;
  TurbulenceLattice mTurbulence;  ///< scratch of addTurbulence()
  MacGrid3 mWindFaces;  ///< mWindField on the faces: the air beyond open sides (inflow.h)
  ScalarGrid mVorticityMagnitude;  ///< |ω|, scratch of vorticity confinement
  Advector mAdvector;
  BlockMask mMask, mMaskTmp;  ///< blocks of cells near smoke (advection skips the rest)
  FlagGrid mCellTypes, mCellTypesNext;
  VectorGrid mSolidVelocity;  ///< velocity of the obstacle in each solid cell
  FlagGrid mNoSlip;           ///< 1 where a solid cell belongs to a no-slip obstacle
  std::vector<Source> mSources;
  std::vector<Obstacle> mObstacles;
  std::vector<PointEmitter> mPointEmitters;
  bool mCellTypesDirty = true;
  bool mHasSolids = false;  ///< some cell is solid (else the boundary stages take a fast path)
  PressureSolver mPressureSolver;
  std::atomic<bool> mCancel{false};
  int mFrame = 0;
  double mTime = 0.0;  ///< seconds since frame 0 at the start of the next step (source noise)
  StepStats mStats;
  std::unique_ptr<AdaptiveDomain> mAdaptive;  ///< params().adaptiveDomain: the box's solver
};

}  // namespace plume
