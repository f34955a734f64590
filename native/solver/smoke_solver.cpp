#include "solver/smoke_solver.h"

#include "core/parallel.h"
#include "solver/adaptive_domain.h"
#include "solver/combustion.h"
#include "solver/forces.h"
#include "solver/inflow.h"
#include "solver/mass_conservation.h"
#include "solver/turbulence.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace plume {
namespace {

/// Breakup's noise streams start here, apart from Flicker's (one stream per source index).
constexpr std::uint64_t kBreakupStream = 0x5EED0000ull;

void checkFinite(const char* name, float v) {
  if (!std::isfinite(v))
    throw std::invalid_argument(std::string(name) + " must be a finite number (got " +
                                std::to_string(v) + ")");
}

void checkCells(const CellSet& set, std::size_t count, const char* what) {
  if (!set.velocity.empty() && set.velocity.size() != set.cells.size())
    throw std::invalid_argument(std::string(what) + ": velocity count differs from cell count");
  for (std::uint32_t c : set.cells)
    if (c >= count) throw std::invalid_argument(std::string(what) + ": cell index out of range");
}

/// `name` in [0, 1], `name`_scale in (0, 1000] m, `name`_rate in [0, 1000] per second.
void checkNoise(const std::string& name, const SourceNoise& noise) {
  if (!(noise.amount >= 0.f && noise.amount <= 1.f))
    throw std::invalid_argument(name + " must be in [0, 1] (got " + std::to_string(noise.amount) +
                                ")");
  if (!(noise.scale > 0.f && noise.scale <= 1e3f))
    throw std::invalid_argument(name + "_scale must be in (0, 1000] m (got " +
                                std::to_string(noise.scale) + ")");
  if (!(noise.rate >= 0.f && noise.rate <= 1e3f))
    throw std::invalid_argument(name + "_rate must be in [0, 1000] per second (got " +
                                std::to_string(noise.rate) + ")");
}

}  // namespace

void SourceSettings::validate() const {
  checkFinite("density", density);
  checkFinite("temperature", temperature);
  checkFinite("fuel", fuel);
  checkFinite("motion_factor", motionFactor);
  for (int a = 0; a < 3; ++a) checkFinite("velocity", velocity[a]);
  checkNoise("fuel_noise", fuelNoise);
  checkNoise("smoke_noise", smokeNoise);
  if (density < 0.f)
    throw std::invalid_argument("density must be >= 0 (got " + std::to_string(density) + ")");
  if (fuel < 0.f)
    throw std::invalid_argument("fuel must be >= 0 (got " + std::to_string(fuel) + ")");
}

SmokeSolver::SmokeSolver(const SmokeParams& params) : mParams(params) {
  mParams.validate();
  const glm::ivec3 n = mParams.resolution;
  mVelocity.resize(n);
  mVelocityTmp.resize(n);
  // One advection result per advected scalar: ρ and T, plus F and S when burning.
  const std::size_t advected = mParams.combustion ? 4 : 2;
  for (std::size_t f = 0; f < advected; ++f) mScalarTmp[f].resize(n);
  for (ScalarGrid* g : {&mDensity, &mTemperature, &mFuel, &mSoot, &mFlame,
                        &mPressure, &mRhs, &mDivergenceTarget})
    g->resize(n);
  mTemperature.fill(mParams.ambientTemperature);
  mVorticity.resize(n);
  mVorticityMagnitude.resize(n);
  mForce.resize(n);
  mCellTypes.resize(n, kFluid);
  mCellTypesNext.resize(n, kFluid);
  mNoSlip.resize(n, 0);
  mSolidVelocity.resize(n, glm::vec3(0.f));
  // Scratch for BFECC must hold the largest face grid.
  const std::size_t largest = std::max({mVelocity.u().count(), mVelocity.v().count(),
                                        mVelocity.w().count()});
  mAdvector.reserve(largest, advected, mParams.advection);
  mPressureSolver.setup(mCellTypes, mParams.boundaries);
  mCellTypesDirty = false;
}

SmokeSolver::~SmokeSolver() = default;

ActiveBox SmokeSolver::activeBox() const {
  return mAdaptive ? mAdaptive->box() : ActiveBox{glm::ivec3(0), mParams.resolution};
}

GridFrame SmokeSolver::gridFrame() const {
  return GridFrame{mParams.resolution, mParams.cellSize, mParams.origin, mParams.frameDt};
}

// ---------------------------------------------------------------------------------------------
// Emitters

void SmokeSolver::clearEmitters() {
  mSources.clear();
  mPointEmitters.clear();
  if (!mObstacles.empty()) mCellTypesDirty = true;
  mObstacles.clear();
}

void SmokeSolver::addSource(const CellSet& cells, const SourceSettings& settings) {
  settings.validate();
  checkCells(cells, mDensity.count(), "source");
  mSources.push_back({cells, settings});
}

void SmokeSolver::addObstacle(const CellSet& cells, Slip slip) {
  checkCells(cells, mDensity.count(), "obstacle");
  mObstacles.push_back({cells, slip});
  mCellTypesDirty = true;
}

void SmokeSolver::setPointEmitters(std::vector<PointEmitter> emitters) {
  const glm::vec3 size = mParams.size();
  const float longest = std::max({size.x, size.y, size.z});
  for (const PointEmitter& e : emitters) {
    e.validate();
    if (e.radius > longest)
      throw std::invalid_argument("point emitter: radius must be at most the domain's longest "
                                  "side, " + std::to_string(longest) + " m (got " +
                                  std::to_string(e.radius) + ")");
  }
  mPointEmitters = std::move(emitters);
}

void SmokeSolver::setWindField(const VectorGrid& wind) {
  if (wind.count() != 0 && wind.size() != mParams.resolution)
    throw std::invalid_argument("wind field must have one vector per cell");
  mWindField = wind;
  // The wind on the faces, for the air that enters through open sides (the face average of the
  // cells on both sides; on the sides of the domain, the cell inside).
  mWindFaces = MacGrid3();
  if (wind.count() == 0) return;
  const glm::ivec3 n = mParams.resolution;
  mWindFaces.resize(n);
  for (int a = 0; a < 3; ++a) {
    ScalarGrid& comp = mWindFaces.component(a);
    const glm::ivec3 fs = comp.size();
    for (int k = 0; k < fs.z; ++k)
      for (int j = 0; j < fs.y; ++j)
        for (int i = 0; i < fs.x; ++i) {
          glm::ivec3 hi(i, j, k), lo(i, j, k);
          lo[a] = std::max(lo[a] - 1, 0);
          hi[a] = std::min(hi[a], n[a] - 1);
          comp(i, j, k) = 0.5f * (wind(lo.x, lo.y, lo.z)[a] + wind(hi.x, hi.y, hi.z)[a]);
        }
  }
}

void SmokeSolver::rebuildCellTypes() {
  if (!mCellTypesDirty) return;
  mCellTypesDirty = false;
  mCellTypesNext.fill(kFluid);
  mNoSlip.fill(0);
  for (const Obstacle& o : mObstacles)
    for (std::size_t n = 0; n < o.cells.cells.size(); ++n) {
      const std::uint32_t c = o.cells.cells[n];
      mCellTypesNext[c] = kSolid;
      mNoSlip[c] = o.slip == Slip::NoSlip ? 1 : 0;
      mSolidVelocity[c] = o.cells.velocity.empty() ? glm::vec3(0.f) : o.cells.velocity[n];
    }
  mHasSolids = std::any_of(mObstacles.begin(), mObstacles.end(),
                           [](const Obstacle& o) { return !o.cells.cells.empty(); });
  // The multigrid hierarchy is rebuilt only when the solid cells really changed (a moving
  // obstacle changes them, a still one re-added every frame does not).
  if (mCellTypesNext.values() != mCellTypes.values()) {
    std::swap(mCellTypes.values(), mCellTypesNext.values());
    // With the adaptive domain the box's solver projects (its own hierarchy).
    if (!mParams.adaptiveDomain) mPressureSolver.setup(mCellTypes, mParams.boundaries);
  }
}

// ---------------------------------------------------------------------------------------------
// Time stepping

bool SmokeSolver::advanceFrame(StepObserver* observer) {
  ThreadLimit limit(mParams.threads);
  const float h = mParams.cellSize;
  int steps = mParams.substeps;
  if (mParams.useCfl) {
    // Enough steps that the fastest face moves at most `cfl` cells per step.
    const float cellsPerFrame = maxSpeed() * mParams.frameDt / h;
    // As a float first: a huge speed must not reach the int cast; a non-finite one (a state
    // that has blown up) adds no steps.
    const float needed = std::ceil(cellsPerFrame / mParams.cfl);
    if (needed < 1000.f) steps = std::max(steps, int(needed));
    else if (std::isfinite(needed)) steps = 1000;
  }
  steps = std::min(steps, 1000);
  const float dt = mParams.frameDt / float(steps);
  // Adaptive domain (adaptive_domain.h): the steps run on the box around the smoke; the public
  // grids are copied in at the start of the frame and back at its end (after each step for an
  // observer, which reads them).
  AdaptiveDomain* box = nullptr;
  if (mParams.adaptiveDomain) {
    rebuildCellTypes();  // the public cell types show this frame's obstacles
    if (!mAdaptive) mAdaptive = std::make_unique<AdaptiveDomain>();
    box = mAdaptive.get();
    box->beginFrame(*this);
  }
  StepStats stats;
  for (int s = 0; s < steps; ++s) {
    const bool stop = observer && observer->cancelRequested();
    if (mCancel.exchange(false) || stop) return false;
    if (observer) observer->beforeStep(*this);
    if (box) {
      box->step(*this, dt);
      mTime += dt;  // the box's solver ran the step on this clock
      mStats = box->lastStats();
      if (observer) box->syncBack(*this);
    } else {
      step(dt);
    }
    if (observer) observer->afterStep(*this, dt);
    stats.pressureIterations += mStats.pressureIterations;
    stats.pressureResidual = std::max(stats.pressureResidual, mStats.pressureResidual);
  }
  if (box) box->syncBack(*this);
  stats.substeps = steps;
  stats.maxSpeed = maxSpeed();
  mStats = stats;
  ++mFrame;
  mTime = double(mFrame) * double(mParams.frameDt);  // no drift from summed steps
  return true;
}

void SmokeSolver::step(float dt) {
  // Stam's fractional step (forces, advection, projection) as named stages. The cycle starts at
  // advection, as Mantaflow's does, so that density and velocity are carried by the
  // divergence-free velocity of the last projection: carried by u + Δt f instead, smoke would
  // be compressed and lose mass wherever buoyancy pushes it.
  using Stage = void (SmokeSolver::*)(float);
  static const std::pair<const char*, Stage> kStages[] = {
      {"sources", &SmokeSolver::applySources}, {"advect", &SmokeSolver::advect},
      {"forces", &SmokeSolver::addForces},     {"burn", &SmokeSolver::burn},
      {"dissipate", &SmokeSolver::dissipate},  {"project", &SmokeSolver::project},
  };
  mStats.pressureIterations = 0;
  mStats.pressureResidual = 0.f;
  for (const auto& stage : kStages) (this->*stage.second)(dt);
  mTime += dt;
}

void SmokeSolver::applySources(float dt) {
  const glm::ivec3 n = mParams.resolution;
  if (!mPointEmitters.empty()) {
    rebuildCellTypes();  // no smoke into the obstacles of this frame
    emitPoints(mPointEmitters, gridFrame(), mParams.ambientTemperature,
               mHasSolids ? &mCellTypes : nullptr, dt, mDensity, mTemperature, mVelocity);
  }
  for (std::size_t index = 0; index < mSources.size(); ++index) {
    const Source& src = mSources[index];
    const SourceSettings& s = src.settings;
    // A source that burns flickers; one that only smokes breaks up.
    const bool burns = mParams.combustion && s.fuel > 0.f;
    const bool flicker = burns && s.fuelNoise.amount > 0.f;
    const bool breakup = !burns && s.smokeNoise.amount > 0.f;
    for (std::size_t m = 0; m < src.cells.cells.size(); ++m) {
      const std::uint32_t c = src.cells.cells[m];
      // Flicker thins the fuel in patches and Breakup the smoke and heat (1 - a n,
      // source_noise.h), each with its own noise stream.
      float thinFuel = 1.f, thinSmoke = 1.f;
      if (flicker || breakup) {
        const glm::ivec3 ijk(int(c % std::uint32_t(n.x)), int((c / std::uint32_t(n.x)) % std::uint32_t(n.y)),
                             int(c / (std::uint32_t(n.x) * std::uint32_t(n.y))));
        const glm::vec3 p = mParams.origin + (glm::vec3(ijk) + 0.5f) * mParams.cellSize;
        if (flicker) thinFuel = sourceNoiseFactor(p, mTime, s.fuelNoise, mParams.seed, index);
        if (breakup)
          thinSmoke = sourceNoiseFactor(p, mTime, s.smokeNoise, mParams.seed,
                                        index + kBreakupStream);
      }
      // Sources keep their cells at least as dense / hot / fuelled as they are set to.
      mDensity[c] = std::max(mDensity[c], thinSmoke * s.density);
      if (s.temperature != 0.f)
        mTemperature[c] =
            std::max(mTemperature[c], mParams.ambientTemperature + thinSmoke * s.temperature);
      if (mParams.combustion) mFuel[c] = std::max(mFuel[c], thinFuel * s.fuel);
      glm::vec3 v = s.velocity;
      if (!src.cells.velocity.empty()) v += s.motionFactor * src.cells.velocity[m];
      if (v == glm::vec3(0.f)) continue;  // a still source leaves the flow alone
      const int i = int(c % std::uint32_t(n.x));
      const int j = int((c / std::uint32_t(n.x)) % std::uint32_t(n.y));
      const int k = int(c / (std::uint32_t(n.x) * std::uint32_t(n.y)));
      mVelocity.u()(i, j, k) = mVelocity.u()(i + 1, j, k) = v.x;
      mVelocity.v()(i, j, k) = mVelocity.v()(i, j + 1, k) = v.y;
      mVelocity.w()(i, j, k) = mVelocity.w()(i, j, k + 1) = v.z;
    }
  }
}

void SmokeSolver::addForces(float dt) {
  rebuildCellTypes();
  // Without solid cells the face loops run without a test per face.
  const FlagGrid* types = mHasSolids ? &mCellTypes : nullptr;
  addBuoyancy(mVelocity, mDensity, mTemperature, types, mParams, dt);
  addWind(mVelocity, mWindField, types, mParams, dt);
  addTurbulence(mVelocity, types, mParams, mTime, dt, mTurbulence);
  Confinement confinement;
  confinement.epsilon = mParams.vorticity;
  if (mParams.combustion) {
    confinement.flameEpsilon = mParams.flameVorticity;
    confinement.fuel = &mFuel;
  }
  addVorticityConfinement(mVelocity, types, confinement, mParams.cellSize, dt, mVorticity, mForce,
                          mVorticityMagnitude);
}

void SmokeSolver::advect(float dt) {
  const Advection scheme = mParams.advection;
  const Interpolation interp = mParams.interpolation;
  // linearVelocity: the velocity is carried with trilinear samples, the scalars with `interp`:
  // the error correction makes trilinear BFECC second order, and on a smooth field it keeps
  // nearly what cubic BFECC keeps (a Gaussian carried around a rotation:
  // advection_velocity_test.cpp). The velocity's are 9 of the 15 cubic passes of a BFECC step,
  // a quarter of its time at 64³; examples/smoke/README.md "Performance".
  const Interpolation velocityInterp = mParams.linearVelocity ? Interpolation::Linear : interp;
  const float h = mParams.cellSize;
  // Scalars first, all carried by the same (pre-advection) velocity along one shared trace.
  struct Field {
    ScalarGrid* grid;
    float background;  ///< value of clean air
    bool conserve;     ///< keep Σ (q - background), less outflow
  };
  // A fixed array, not a vector: step() never allocates. Heat, Σ (T - T_amb), is conserved like
  // the densities: advection alone drifts it as much as it drifts ρ (+14% in 12 frames of a
  // closed-box test with semi-Lagrangian steps, +31% in 55 frames with BFECC).
  const Field scalars[] = {{&mDensity, 0.f, mParams.conserveMass},
                           {&mTemperature, mParams.ambientTemperature, mParams.conserveMass},
                           {&mFuel, 0.f, mParams.conserveMass},
                           {&mSoot, 0.f, mParams.conserveMass}};
  const std::size_t fieldCount = mParams.combustion ? 4 : 2;  // fuel and soot only burn
  // Blocks far from any smoke stay clean air exactly, as long as nothing travels further than
  // the mask's dilation in one step (BFECC reaches twice the trace plus two stencils): at least
  // kDilation blocks, more for a long step (one step a frame) rather than no mask at all.
  const float reach = 2.f * maxSpeed() * dt / h + 4.f;
  constexpr int kMostBlocks = 6;  // beyond it the dilated mask is about the whole grid
  // Compared as a float first: a huge (or non-finite) speed must not reach the int cast.
  const float reachBlocks = reach / float(BlockMask::kBlock);
  const int blocks = reachBlocks < float(kMostBlocks)
                         ? std::max(BlockMask::kDilation, int(reachBlocks) + 1)
                         : kMostBlocks + 1;
  const BlockMask* mask = nullptr;
  if (blocks <= kMostBlocks && reach < float(blocks * BlockMask::kBlock)) {
    mMask.build(*scalars[0].grid, scalars[0].background, blocks);
    for (std::size_t f = 1; f < fieldCount; ++f) {
      mMaskTmp.build(*scalars[f].grid, scalars[f].background, blocks);
      mMask.merge(mMaskTmp);
    }
    mask = &mMask;
  }
  // Air entering through an open side is ambient air (inflow.h): clean, at T_amb, still or
  // moving with the wind.
  const std::uint8_t open = openSides(mParams.boundaries);
  mAdvector.trace(mVelocity, mParams.resolution, kCellOffset, dt, h, scheme, mask, mParams.trace,
                  open);
  // All scalars in one advect() call: each run's split trace is read once for all of them.
  // The totals of the conserved ones are summed in one pass before and one after.
  static_assert(Advector::kMaxFields <= kMaxMassFields, "every scalar may be conserved");
  ScalarGrid* conserved[Advector::kMaxFields];
  float backgrounds[Advector::kMaxFields];
  double targets[Advector::kMaxFields], masses[Advector::kMaxFields];
  float peaks[Advector::kMaxFields];
  std::size_t conservedCount = 0;
  Advector::Field carried[Advector::kMaxFields];
  for (std::size_t m = 0; m < fieldCount; ++m) {
    const Field& f = scalars[m];
    if (f.conserve) {
      conserved[conservedCount] = f.grid;
      backgrounds[conservedCount++] = f.background;
    }
    carried[m] = {f.grid, &mScalarTmp[m], f.background};
  }
  mAdvector.advect(carried, fieldCount, interp, mask);
  // The totals before advection are taken now, from the unchanged sources that advection has
  // just read (in cache, where before it they were not: a pass over a cold field costs as much
  // as the sum itself). Outside the mask every field is its background value, before and after.
  double outflow[Advector::kMaxFields];
  totalMasses(conserved, backgrounds, conservedCount, targets, nullptr, mask);
  outflowMasses(conserved, backgrounds, conservedCount, mVelocity, mParams.boundaries, dt, h,
                outflow);
  for (std::size_t m = 0; m < conservedCount; ++m) targets[m] -= outflow[m];
  for (std::size_t m = 0; m < fieldCount; ++m)
    std::swap(scalars[m].grid->values(), mScalarTmp[m].values());
  totalMasses(conserved, backgrounds, conservedCount, masses, peaks, mask);
  restoreMasses(conserved, targets, backgrounds, conservedCount, masses, peaks, nullptr, mask);
  // Then each velocity component along the trace of its own faces.
  static const glm::vec3 kOffsets[3] = {kFaceOffsetU, kFaceOffsetV, kFaceOffsetW};
  const bool windy = mParams.windStrength > 0.f;
  const bool windField = windy && mWindField.count() != 0;
  for (int a = 0; a < 3; ++a) {
    const ScalarGrid& comp = mVelocity.component(a);
    mAdvector.trace(mVelocity, comp.size(), kOffsets[a], dt, h, scheme, nullptr, mParams.trace,
                    open);
    const float ambient = windy && !windField ? mParams.wind[a] : 0.f;
    mAdvector.advect(comp, mVelocityTmp.component(a), velocityInterp, nullptr, ambient,
                     windField ? &mWindFaces.component(a) : nullptr);
  }
  std::swap(mVelocity, mVelocityTmp);
  if (!mObstacles.empty()) zeroSolidScalars();
}

void SmokeSolver::burn(float dt) {
  if (!mParams.combustion) return;
  burnFuel(mFuel, mSoot, mTemperature, mFlame, mDivergenceTarget, mCellTypes, mParams, dt);
  coolAndConduct(mTemperature, mScalarTmp[0], mCellTypes, mParams, dt);
}

void SmokeSolver::dissipate(float dt) {
  if (mParams.densityDissipation <= 0.f) return;
  const float keep = std::exp(-mParams.densityDissipation * dt);
  const glm::ivec3 n = mParams.resolution;
  const std::size_t slice = std::size_t(n.x) * std::size_t(n.y);
  parallelFor(0, n.z, [&](int k) {
    for (std::size_t c = std::size_t(k) * slice, e = c + slice; c < e; ++c) mDensity[c] *= keep;
  });
}

void SmokeSolver::zeroSolidScalars() {
  const glm::ivec3 n = mParams.resolution;
  const std::size_t slice = std::size_t(n.x) * std::size_t(n.y);
  parallelFor(0, n.z, [&](int k) {
    for (std::size_t c = std::size_t(k) * slice, e = c + slice; c < e; ++c)
      if (mCellTypes[c] != kFluid) {
        mDensity[c] = mFuel[c] = mSoot[c] = mFlame[c] = 0.f;
        mTemperature[c] = mParams.ambientTemperature;
      }
  });
}

}  // namespace plume
