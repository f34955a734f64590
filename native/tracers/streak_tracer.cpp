#include "tracers/streak_tracer.h"

#include "core/parallel.h"
#include "solver/smoke_solver.h"
#include "tracers/domain_sides.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace plume {
namespace {

/// Particles per parallel task: enough work to pay for the task, small enough to balance.
constexpr int kChunk = 256;

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::string sizeText(glm::ivec3 s) {
  return std::to_string(s.x) + "x" + std::to_string(s.y) + "x" + std::to_string(s.z);
}

}  // namespace

void StreakParams::validate() const {
  if (emissionPeriod < 1 || emissionPeriod > kMaxEmissionPeriod)
    throw std::invalid_argument("emission_period must be in [1, " +
                                std::to_string(kMaxEmissionPeriod) + "] steps (got " +
                                std::to_string(emissionPeriod) + ")");
  if (interpolation != Interpolation::Linear && interpolation != Interpolation::MonotonicCubic)
    throw std::invalid_argument("interpolation must be LINEAR or MONOTONIC_CUBIC");
}

StreakTracer::StreakTracer(const StreakParams& params, const GridFrame& grid,
                           const std::array<Boundary, 6>& boundaries)
    : mParams(params), mGrid(grid), mBoundaries(boundaries) {
  mParams.validate();
  if (grid.resolution.x < 1 || grid.resolution.y < 1 || grid.resolution.z < 1)
    throw std::invalid_argument("resolution must be >= 1 cell per axis (got " +
                                sizeText(grid.resolution) + ")");
  if (!(grid.cellSize > 0.f) || !std::isfinite(grid.cellSize))
    throw std::invalid_argument("cell_size must be a finite number > 0 (got " +
                                std::to_string(grid.cellSize) + ")");
  if (!finite(grid.origin)) throw std::invalid_argument("origin must be finite");
  mInvCellSize = 1.f / grid.cellSize;
  mLo = grid.origin;
  mHi = grid.origin + glm::vec3(grid.resolution) * grid.cellSize;
}

StreakTracer::StreakTracer(const StreakParams& params, const SmokeParams& smoke)
    : StreakTracer(params,
                   GridFrame{smoke.resolution, smoke.cellSize, smoke.origin, smoke.frameDt},
                   smoke.boundaries) {}

int StreakTracer::addPointSources(const std::vector<glm::vec3>& positions,
                                  const std::vector<int>& groups,
                                  const std::vector<glm::vec3>& velocities) {
  if (mState.steps != 0)
    throw std::invalid_argument(
        "point sources must be added before the first step (every streakline needs the same "
        "particle count)");
  if (groups.size() != positions.size())
    throw std::invalid_argument("point sources: " + std::to_string(groups.size()) + " groups for " +
                                std::to_string(positions.size()) + " positions");
  if (!velocities.empty() && velocities.size() != positions.size())
    throw std::invalid_argument("point sources: " + std::to_string(velocities.size()) +
                                " velocities for " + std::to_string(positions.size()) + " positions");
  for (std::size_t n = 0; n < positions.size(); ++n)
    checkPointSource(n, positions[n], velocities.empty() ? glm::vec3(0.f) : velocities[n]);
  const int first = int(mState.sources.size());
  for (std::size_t n = 0; n < positions.size(); ++n) {
    mState.sources.push_back(
        {positions[n], groups[n], velocities.empty() ? glm::vec3(0.f) : velocities[n]});
    // Emission 0 (instant t = 0). Before the first step the storage holds only emission 0, so
    // appending keeps the emission-major layout. Density is unknown until the first step.
    mState.positions.push_back(positions[n]);
    mState.density.push_back(0.f);
    mState.outside.push_back(0);
    mState.exitVelocity.emplace_back(0.f);
  }
  return first;
}

void StreakTracer::checkPointSource(std::size_t n, glm::vec3 p, glm::vec3 velocity) const {
  if (!finite(p) || !finite(velocity))
    throw std::invalid_argument("point source " + std::to_string(n) +
                                ": position and velocity must be finite");
  if (glm::any(glm::lessThan(p, mLo)) || glm::any(glm::greaterThan(p, mHi)))
    throw std::invalid_argument("point source " + std::to_string(n) + " at (" +
                                std::to_string(p.x) + ", " + std::to_string(p.y) + ", " +
                                std::to_string(p.z) + ") lies outside the domain");
}

void StreakTracerState::validate(int emissionPeriod) const {
  if (emissionPeriod < 1) throw std::invalid_argument("emission_period must be >= 1");
  // Rows: the first, then at most one per emission instant up to the youngest row's step.
  if (steps < 0 || emissions < 1 || lastEmissionStep < 0 || lastEmissionStep > steps ||
      lastEmissionStep % emissionPeriod != 0 ||
      (emissions == 1) != (lastEmissionStep == 0) ||
      emissions - 1 > lastEmissionStep / emissionPeriod)
    throw std::invalid_argument("tracer state: " + std::to_string(emissions) +
                                " emissions, the youngest at step " +
                                std::to_string(lastEmissionStep) + ", after " +
                                std::to_string(steps) + " steps do not match emission period " +
                                std::to_string(emissionPeriod));
  const std::size_t m = sources.size() * std::size_t(emissions);
  if (sources.size() != 0 && m / sources.size() != std::size_t(emissions))
    throw std::invalid_argument("tracer state: too many particles");
  if (positions.size() != m || density.size() != m || outside.size() != m ||
      exitVelocity.size() != m)
    throw std::invalid_argument("tracer state: " + std::to_string(sources.size()) + " sources x " +
                                std::to_string(emissions) + " emissions need " +
                                std::to_string(m) + " particles in every array");
  for (std::size_t n = 0; n < m; ++n)
    if (outside[n] > 1 || !finite(positions[n]) || !finite(exitVelocity[n]) ||
        !std::isfinite(density[n]))
      throw std::invalid_argument("tracer state: particle " + std::to_string(n) +
                                  " has a non-finite value or a bad outside flag");
}

void StreakTracer::setState(StreakTracerState state) {
  state.validate(mParams.emissionPeriod);
  for (std::size_t n = 0; n < state.sources.size(); ++n)
    checkPointSource(n, state.sources[n].position, state.sources[n].velocity);
  mState = std::move(state);
}

void StreakTracer::checkGrid(glm::ivec3 size, glm::ivec3 expected, const char* what) const {
  if (size != expected)
    throw std::invalid_argument(std::string("streak tracer: ") + what + " grid is " +
                                sizeText(size) + "; expected " + sizeText(expected));
}

void StreakTracer::emit() {
  for (const PointSource& s : mState.sources) {
    mState.positions.push_back(s.position);
    mState.density.push_back(0.f);
    mState.outside.push_back(0);
    mState.exitVelocity.emplace_back(0.f);
  }
  ++mState.emissions;
  mState.lastEmissionStep = mState.steps;
}

void StreakTracer::step(const MacGrid3& before, const MacGrid3& after, const ScalarGrid& density,
                        float dt) {
  if (!(dt > 0.f) || !std::isfinite(dt))
    throw std::invalid_argument("dt must be a finite number > 0 (got " + std::to_string(dt) + ")");
  checkGrid(before.cells(), mGrid.resolution, "start-of-step velocity");
  checkGrid(after.cells(), mGrid.resolution, "end-of-step velocity");
  checkGrid(density.size(), mGrid.resolution, "density");
  const Interpolation scheme = mParams.interpolation;
  const int sources = sourceCount();
  // Particles of an emission made at this step's start are newborn (none after a paused instant).
  const std::size_t newborn = mState.lastEmissionStep == mState.steps
                                  ? std::size_t(mState.emissions - 1) * std::size_t(sources)
                                  : mState.positions.size();
  const int count = int(mState.positions.size());
  const float half = 0.5f * dt;
  parallelFor(0, (count + kChunk - 1) / kChunk, [&](int chunk) {
    const int end = std::min(count, (chunk + 1) * kChunk);
    for (int n = chunk * kChunk; n < end; ++n) {
      const glm::vec3 x = mState.positions[std::size_t(n)];
      if (mState.outside[std::size_t(n)]) {
        // No air is simulated out there: the particle keeps the velocity it left with, so a
        // streakline leaving the domain stays evenly spaced instead of piling up on the side
        // (a pile of coincident particles makes the interpolating surface overshoot).
        mState.positions[std::size_t(n)] = x + dt * mState.exitVelocity[std::size_t(n)];
        continue;
      }
      glm::vec3 k1(0.f);
      if (std::size_t(n) >= newborn)
        k1 = mState.sources[std::size_t(n) % std::size_t(sources)].velocity;
      if (k1 == glm::vec3(0.f)) k1 = sampleVelocity(before, toCell(x), scheme);
      const glm::vec3 xm = x + half * k1;
      const glm::vec3 cm = toCell(xm);
      // The field at t + ½Δt: mean of the fields at t and t + Δt (second order in time).
      const glm::vec3 um = 0.5f * (sampleVelocity(before, cm, scheme) + sampleVelocity(after, cm, scheme));
      glm::vec3 xn = x + dt * um;
      if (!finite(xn)) xn = x;  // a broken field must not poison the cache
      // A closed side holds the particle on it; through an open side it leaves.
      const bool left = applyDomainSides(xn, mLo, mHi, mBoundaries);
      mState.positions[std::size_t(n)] = xn;
      if (left) {
        mState.outside[std::size_t(n)] = 1;
        mState.exitVelocity[std::size_t(n)] = um;
        mState.density[std::size_t(n)] = 0.f;  // no smoke is simulated outside the domain
      }
    }
  });
  ++mState.steps;
  if (mState.steps % mParams.emissionPeriod == 0 && mState.emitting) emit();
  // Density at every particle still inside, at the end of the step (§3.2: stored every step).
  const int total = int(mState.positions.size());
  parallelFor(0, (total + kChunk - 1) / kChunk, [&](int chunk) {
    const int end = std::min(total, (chunk + 1) * kChunk);
    for (int n = chunk * kChunk; n < end; ++n)
      if (!mState.outside[std::size_t(n)])
        mState.density[std::size_t(n)] =
            sample(density, toCell(mState.positions[std::size_t(n)]), scheme);
  });
}

void StreakTracer::observeStep(const SmokeSolver& solver, const MacGrid3& velocityBefore,
                               float dt) {
  const GridFrame g = solver.gridFrame();
  if (g.resolution != mGrid.resolution || g.cellSize != mGrid.cellSize || g.origin != mGrid.origin)
    throw std::invalid_argument("streak tracer: the solver's domain differs from the tracer's");
  step(velocityBefore, solver.velocity(), solver.density(), dt);
}

StreakFrame StreakTracer::snapshot() const {
  StreakFrame f;
  const std::size_t sources = mState.sources.size(), emissions = std::size_t(mState.emissions);
  f.counts.assign(sources, mState.emissions);
  f.groups.reserve(sources);
  for (const PointSource& s : mState.sources) f.groups.push_back(s.group);
  f.positions.resize(mState.positions.size());
  f.density.resize(mState.positions.size());
  f.outside.resize(mState.positions.size());
  // Emission-major storage to source-major snapshot, oldest particle first.
  for (std::size_t s = 0; s < sources; ++s)
    for (std::size_t e = 0; e < emissions; ++e) {
      const std::size_t from = e * sources + s, to = s * emissions + e;
      f.positions[to] = mState.positions[from];
      f.density[to] = mState.density[from];
      f.outside[to] = mState.outside[from];
    }
  return f;
}

}  // namespace plume
