#include "flowgraph/pathline_recorder.h"

#include "core/parallel.h"
#include "core/sampling.h"
#include "flowgraph/pathline_integrator.h"
#include "tracers/domain_sides.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

/// Particles per parallel task.
constexpr int kChunk = 256;

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

void PathlineParams::validate() const {
  if (nodesPerFrame < 1 || nodesPerFrame > kMaxNodesPerFrame)
    throw std::invalid_argument("nodes_per_frame must be in [1, " +
                                std::to_string(kMaxNodesPerFrame) + "] (got " +
                                std::to_string(nodesPerFrame) + ")");
  if (!(lifetime > 0.f) || !std::isfinite(lifetime))
    throw std::invalid_argument("pathline lifetime must be a finite number of seconds > 0 (got " +
                                std::to_string(lifetime) + ")");
}

int PathlineParams::samples(float frameDt) const {
  const double dtn = double(frameDt) / double(nodesPerFrame);
  const double l = std::round(double(lifetime) / dtn);
  if (!(l >= 2.0) || l > double(kMaxPathlineSampleCount))
    throw std::invalid_argument(
        "pathline lifetime must hold 2 to " + std::to_string(kMaxPathlineSampleCount) +
        " node steps of " + std::to_string(dtn) + " s (got " + std::to_string(lifetime) + " s)");
  return int(l);
}

std::vector<glm::vec3> pathlineSeeds(const CellSet& cells, glm::ivec3 resolution, float cellSize,
                                     glm::vec3 origin) {
  if (cells.cells.empty())
    throw std::invalid_argument("pathlines need a fuel-injection region: no source cell injects fuel");
  const std::uint64_t count =
      std::uint64_t(resolution.x) * std::uint64_t(resolution.y) * std::uint64_t(resolution.z);
  std::vector<std::uint32_t> sorted = cells.cells;
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  std::vector<glm::vec3> seeds;
  seeds.reserve(sorted.size() * 8);
  const auto nx = std::uint64_t(resolution.x), ny = std::uint64_t(resolution.y);
  for (std::uint32_t c : sorted) {
    if (c >= count)
      throw std::invalid_argument("fuel cell index " + std::to_string(c) +
                                  " is outside the grid of " + std::to_string(count) + " cells");
    const glm::vec3 corner(float(c % nx), float((c / nx) % ny), float(c / (nx * ny)));
    // §4.2: "uniformly distributed and the interval is half the grid resolution Δx".
    for (int k = 0; k < 2; ++k)
      for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i)
          seeds.push_back(origin + (corner + glm::vec3(0.25f + 0.5f * float(i), 0.25f + 0.5f * float(j),
                                                      0.25f + 0.5f * float(k))) *
                                       cellSize);
  }
  return seeds;
}

/// What the samples of one instant read: the substep's velocity (θ blends its start and end),
/// and density + soot and temperature at its end, blended with the copies of its start.
struct PathlineRecorder::Fields {
  SubstepVelocity velocity;
  const ScalarGrid& densityStart;
  const ScalarGrid& temperatureStart;
  const SmokeSolver& end;
  glm::vec3 origin;
  float invCellSize;

  /// R (density + soot) and T at x, at substep fraction θ (θ = 1 reads the end fields only).
  void scalars(glm::vec3 x, float theta, float& density, float& temperature) const {
    const glm::vec3 c = (x - origin) * invCellSize - glm::vec3(0.5f);
    const float r1 = sampleLinear(end.density(), c) + sampleLinear(end.soot(), c);
    const float t1 = sampleLinear(end.temperature(), c);
    if (theta >= 1.f) {
      density = r1;
      temperature = t1;
      return;
    }
    const float s = 1.f - theta;
    density = s * sampleLinear(densityStart, c) + theta * r1;
    temperature = s * sampleLinear(temperatureStart, c) + theta * t1;
  }
};

PathlineRecorder::PathlineRecorder(const PathlineParams& params, const SmokeParams& smoke,
                                   const CellSet& fuelCells, PathlineSink sink)
    : mParams(params), mSink(std::move(sink)) {
  mParams.validate();
  smoke.validate();
  if (!mSink) throw std::invalid_argument("pathline recorder needs a sink for its groups");
  mResolution = smoke.resolution;
  mCellSize = smoke.cellSize;
  mFrameDt = smoke.frameDt;
  mOrigin = smoke.origin;
  mLo = smoke.origin;
  mHi = smoke.origin + smoke.size();
  mBoundaries = smoke.boundaries;
  mSeeds = pathlineSeeds(fuelCells, smoke.resolution, smoke.cellSize, smoke.origin);
  if (mSeeds.size() > std::size_t(1) << 30)
    throw std::invalid_argument("too many fuel cells for pathlines");
  mLayout.particles = int(mSeeds.size());
  mLayout.samples = mParams.samples(smoke.frameDt);
  mLayout.sampleDt = float(double(smoke.frameDt) / double(mParams.nodesPerFrame));
  mLive.resize(std::size_t(mLayout.samples));
}

void PathlineRecorder::checkSolver(const SmokeSolver& solver) const {
  const SmokeParams& p = solver.params();
  if (p.resolution != mResolution || p.cellSize != mCellSize || p.origin != mOrigin ||
      p.frameDt != mFrameDt)
    throw std::invalid_argument("pathline recorder: the solver's domain or frame differs from the "
                                "recorder's");
}

void PathlineRecorder::beforeStep(const SmokeSolver& solver) {
  checkSolver(solver);
  if (solver.frame() != mFrame) {
    mFrame = solver.frame();
    mSubstep = 0;
  }
  // The solver keeps only the newest velocity: the start of the substep is copied here (the
  // buffers are reused after the first step) so the particles see u blended in time.
  mVelocityStart = solver.velocity();
  if (mParams.nodesPerFrame > 1 || mSeeded == 0) {
    // Node times inside a substep blend the scalars too.
    const std::size_t n = solver.density().count();
    mDensityStart.reshape(solver.density().size());
    mTemperatureStart.reshape(solver.temperature().size());
    const float* d = solver.density().data();
    const float* s = solver.soot().data();
    float* out = mDensityStart.data();
    const int slabs = (int(n) + 65535) / 65536;
    parallelFor(0, slabs, [&](int b) {
      const std::size_t e = std::min(n, std::size_t(b + 1) * 65536);
      for (std::size_t m = std::size_t(b) * 65536; m < e; ++m) out[m] = d[m] + s[m];
    });
    std::copy(solver.temperature().values().begin(), solver.temperature().values().end(),
              mTemperatureStart.values().begin());
  }
  if (mSeeded == 0) {
    // Node 0 is the instant before the first step: start and end are the same state.
    const Fields f{SubstepVelocity(mVelocityStart, mVelocityStart, mCellSize, mOrigin),
                   mDensityStart, mTemperatureStart, solver, mOrigin, 1.f / mCellSize};
    nodeTime(f, 0.f);
  }
}

void PathlineRecorder::afterStep(const SmokeSolver& solver, float dt) {
  const double ratio = double(mFrameDt) / double(dt);
  const int steps = int(std::lround(ratio));
  if (steps < 1 || std::fabs(ratio - double(steps)) > 1e-3 * ratio)
    throw std::logic_error("pathline recorder: a step of " + std::to_string(dt) +
                           " s is not a whole fraction of the frame");
  const int s = mSubstep++;
  const int npf = mParams.nodesPerFrame;
  const Fields f{SubstepVelocity(mVelocityStart, solver.velocity(), mCellSize, mOrigin),
                 mDensityStart, mTemperatureStart, solver, mOrigin, 1.f / mCellSize};
  // Node j of this frame is at frame fraction j / npf; it lies in this substep, which spans
  // fractions (s / steps, (s + 1) / steps], when s npf < j steps <= (s + 1) npf (exact
  // integers, so the node at the frame's end always falls on its last substep's end).
  float thetaA = 0.f;
  for (int j = 1; j <= npf; ++j) {
    const long long at = (long long)j * steps;
    if (at <= (long long)s * npf || at > (long long)(s + 1) * npf) continue;
    const long long num = at - (long long)s * npf;
    const float theta = num == npf ? 1.f : float(double(num) / double(npf));
    moveLive(f, thetaA, theta, dt);
    nodeTime(f, theta);
    thetaA = theta;
  }
  if (thetaA < 1.f) moveLive(f, thetaA, 1.f, dt);
}

void PathlineRecorder::moveLive(const Fields& f, float thetaA, float thetaB, float dt) {
  if (!(thetaB > thetaA)) return;
  const int P = mLayout.particles;
  const int chunksPerGroup = (P + kChunk - 1) / kChunk;
  const int first = mCompleted;
  parallelFor(0, liveCount() * chunksPerGroup, [&](int task) {
    Live& g = slot(first + task / chunksPerGroup);
    const int begin = (task % chunksPerGroup) * kChunk, end = std::min(P, begin + kChunk);
    for (int p = begin; p < end; ++p) {
      if (g.left[std::size_t(p)]) continue;
      const glm::vec3 x = g.position[std::size_t(p)];
      glm::vec3 xn = advancePathline(f.velocity, x, thetaA, thetaB, dt, mCellSize);
      if (!finite(xn)) xn = x;  // a broken field must not poison the file
      // One that left keeps its last position inside (pathline_group.h).
      if (applyDomainSides(xn, mLo, mHi, mBoundaries)) g.left[std::size_t(p)] = 1;
      else g.position[std::size_t(p)] = xn;
    }
  });
}

void PathlineRecorder::nodeTime(const Fields& f, float theta) {
  const int P = mLayout.particles, L = mLayout.samples;
  const int chunksPerGroup = (P + kChunk - 1) / kChunk;
  const bool trail = mParams.recordPositions;
  // Sample `count` groups from node `first` on, each at its own next sample.
  auto sampleGroups = [&](int first, int count) {
    parallelFor(0, count * chunksPerGroup, [&](int task) {
      Live& g = slot(first + task / chunksPerGroup);
      const std::size_t s = std::size_t(g.taken);
      const int begin = (task % chunksPerGroup) * kChunk, end = std::min(P, begin + kChunk);
      for (int p = begin; p < end; ++p) {
        const std::size_t i = std::size_t(p) * std::size_t(L) + s;
        const glm::vec3 x = g.position[std::size_t(p)];
        if (trail) g.trail[i] = x;
        if (g.left[std::size_t(p)]) {
          // Outside the domain nothing is simulated: the particle has dissipated.
          g.group.velocity[i] = glm::vec3(0.f);
          g.group.density[i] = g.group.temperature[i] = 0.f;
          continue;
        }
        g.group.velocity[i] = f.velocity.at(x, theta);
        f.scalars(x, theta, g.group.density[i], g.group.temperature[i]);
      }
    });
    for (int k = first; k < first + count; ++k) ++slot(k).taken;
  };
  sampleGroups(mCompleted, liveCount());
  // Groups with L samples are complete, in node order.
  while (liveCount() > 0 && slot(mCompleted).taken == L) {
    Live& g = slot(mCompleted);
    mSink(g.group, g.trail);
    ++mCompleted;
  }
  seed();
  sampleGroups(mSeeded - 1, 1);
}

void PathlineRecorder::seed() {
  Live& g = slot(mSeeded);
  const std::size_t P = mSeeds.size(), values = mLayout.values();
  // Same sizes every time: after the first L groups no buffer is reallocated.
  g.group.state = 0;
  g.group.step = mSeeded;
  g.group.layout = mLayout;
  g.group.start = mSeeds;
  g.group.velocity.resize(values);
  g.group.density.resize(values);
  g.group.temperature.resize(values);
  g.position = mSeeds;
  g.left.assign(P, 0);
  if (mParams.recordPositions) g.trail.resize(values);
  g.taken = 0;
  ++mSeeded;
}

}  // namespace plume
