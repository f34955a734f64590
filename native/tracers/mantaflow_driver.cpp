#include "tracers/mantaflow_driver.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/parallel.h"

namespace plume {
namespace {

/// The tracer's frame: Mantaflow's index space (cell (i,j,k) spans [i, i+1] on each axis).
GridFrame indexFrame(const MantaflowGrid& grid) {
  grid.validate();
  return GridFrame{grid.resolution, /*cellSize=*/1.f, /*origin=*/glm::vec3(0.f), /*frameDt=*/1.f};
}

std::string vecText(glm::vec3 p) {
  return "(" + std::to_string(p.x) + ", " + std::to_string(p.y) + ", " + std::to_string(p.z) + ")";
}

}  // namespace

void MantaflowTraceParams::validate() const {
  streak.validate();
  if (!(cfl >= kMinTraceCfl && cfl <= kMaxTraceCfl))
    throw std::invalid_argument("trace cfl must be in [" + std::to_string(kMinTraceCfl) + ", " +
                                std::to_string(kMaxTraceCfl) + "] cells per substep (got " +
                                std::to_string(cfl) + ")");
}

MantaflowTracer::MantaflowTracer(const MantaflowTraceParams& params, const MantaflowGrid& grid,
                                 const std::array<Boundary, 6>& boundaries)
    : mParams(params), mGrid(grid), mTracer(params.streak, indexFrame(grid), boundaries) {
  mParams.validate();
}

int MantaflowTracer::addPointSources(const std::vector<glm::vec3>& worldPositions,
                                     const std::vector<int>& groups) {
  const glm::vec3 hi = mGrid.indexToWorld(glm::vec3(mGrid.resolution));
  std::vector<glm::vec3> cells(worldPositions.size());
  for (std::size_t n = 0; n < worldPositions.size(); ++n) {
    const glm::vec3 p = worldPositions[n];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw std::invalid_argument("point source " + std::to_string(n) +
                                  ": position must be finite");
    if (glm::any(glm::lessThan(p, mGrid.origin)) || glm::any(glm::greaterThan(p, hi)))
      throw std::invalid_argument("point source " + std::to_string(n) + " at " + vecText(p) +
                                  " lies outside the Mantaflow domain " + vecText(mGrid.origin) +
                                  " - " + vecText(hi));
    // Rounding of the division must not carry a point on the box's side out of it.
    cells[n] = glm::clamp(mGrid.worldToIndex(p), glm::vec3(0.f), glm::vec3(mGrid.resolution));
  }
  return mTracer.addPointSources(cells, groups, {});
}

int MantaflowTracer::substeps(const MantaflowFrame& a, const MantaflowFrame& b,
                              float frameDt) const {
  if (!(frameDt > 0.f) || !std::isfinite(frameDt))
    throw std::invalid_argument("frame_dt must be a finite number > 0 (got " +
                                std::to_string(frameDt) + ")");
  for (const MantaflowFrame* f : {&a, &b})
    if (f->density.size() != mGrid.resolution || f->velocity.cells() != mGrid.resolution)
      throw std::invalid_argument("Mantaflow trace: a frame is not on the tracer's grid");
  const double speed = std::max(a.maxCellsPerSecond(mGrid), b.maxCellsPerSecond(mGrid));
  const double n = std::ceil(speed * double(frameDt) / double(mParams.cfl));
  if (!(n <= double(kMaxTraceSubsteps)))
    throw std::runtime_error("Mantaflow trace: a speed of " + std::to_string(speed * frameDt) +
                             " cells per frame would need more than " +
                             std::to_string(kMaxTraceSubsteps) + " substeps (a broken cache?)");
  return std::max(1, int(n));
}

void MantaflowTracer::blend(const MantaflowFrame& a, const MantaflowFrame& b, float t,
                            MacGrid3& out) const {
  out.resize(mGrid.resolution);  // no reallocation after the first call
  for (int c = 0; c < 3; ++c) {
    const ScalarGrid& ua = a.velocity.component(c);
    const ScalarGrid& ub = b.velocity.component(c);
    ScalarGrid& o = out.component(c);
    const float wa = (1.f - t) / mGrid.cellSize[c], wb = t / mGrid.cellSize[c];
    const glm::ivec3 s = o.size();
    const std::size_t slab = std::size_t(s.x) * std::size_t(s.y);
    parallelFor(0, s.z, [&](int k) {
      for (std::size_t m = std::size_t(k) * slab, e = m + slab; m < e; ++m)
        o[m] = wa * ua[m] + wb * ub[m];
    });
  }
}

int MantaflowTracer::advanceFrame(const MantaflowFrame& a, const MantaflowFrame& b, float frameDt) {
  const int n = substeps(a, b, frameDt);
  const float dt = frameDt / float(n);
  blend(a, b, 0.f, mStart);
  for (int s = 0; s < n; ++s) {
    if (mTracer.consumeCancel()) return 0;
    blend(a, b, float(s + 1) / float(n), mEnd);
    // Density is only observable after the frame's last substep, where it is b's exactly.
    mTracer.step(mStart, mEnd, b.density, dt);
    std::swap(mStart, mEnd);
  }
  return n;
}

StreakFrame MantaflowTracer::snapshot() const {
  StreakFrame f = mTracer.snapshot();
  for (glm::vec3& p : f.positions) p = mGrid.indexToWorld(p);
  return f;
}

}  // namespace plume
