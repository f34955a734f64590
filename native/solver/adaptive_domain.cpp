#include "solver/adaptive_domain.h"

#include "solver/smoke_solver.h"

#include <algorithm>
#include <cmath>

namespace plume {
namespace {

glm::ivec3 cellOf(std::uint32_t c, glm::ivec3 n) {
  return {int(c % std::uint32_t(n.x)), int((c / std::uint32_t(n.x)) % std::uint32_t(n.y)),
          int(c / (std::uint32_t(n.x) * std::uint32_t(n.y)))};
}

/// The cells of `set` inside `box`, as indices of the box's grid (velocities alongside).
CellSet cropCells(const CellSet& set, glm::ivec3 n, const ActiveBox& box) {
  CellSet out;
  const glm::ivec3 b = box.size();
  for (std::size_t m = 0; m < set.cells.size(); ++m) {
    const glm::ivec3 c = cellOf(set.cells[m], n) - box.lo;
    if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c, b)))
      continue;
    out.cells.push_back(std::uint32_t(c.x + b.x * (c.y + b.y * c.z)));
    if (!set.velocity.empty()) out.velocity.push_back(set.velocity[m]);
  }
  return out;
}

/// Box of the cells of `set` (only those with a non-zero velocity when `movingOnly`).
ActiveBox boxOfCells(const CellSet& set, glm::ivec3 n, bool movingOnly) {
  ActiveBox box;
  for (std::size_t m = 0; m < set.cells.size(); ++m) {
    if (movingOnly && (set.velocity.empty() || set.velocity[m] == glm::vec3(0.f))) continue;
    const glm::ivec3 c = cellOf(set.cells[m], n);
    box = box.withCells(c, c, n);
  }
  return box;
}

/// Params of the solver of `box`: the full domain's, on the box, with Open inner sides.
SmokeParams boxParams(const SmokeParams& full, const ActiveBox& box) {
  SmokeParams p = full;
  p.adaptiveDomain = false;
  p.resolution = box.size();
  p.origin = full.origin + glm::vec3(box.lo) * full.cellSize;
  for (int a = 0; a < 3; ++a) {
    if (box.lo[a] != 0) p.boundaries[std::size_t(2 * a)] = Boundary::Open;
    if (box.hi[a] != full.resolution[a]) p.boundaries[std::size_t(2 * a + 1)] = Boundary::Open;
  }
  return p;
}

}  // namespace

AdaptiveDomain::AdaptiveDomain() = default;
AdaptiveDomain::~AdaptiveDomain() = default;

const StepStats& AdaptiveDomain::lastStats() const { return mInner->lastStats(); }

ActiveBox AdaptiveDomain::boxFor(const SmokeSolver& full, bool fromInner) const {
  const SmokeParams& p = full.params();
  const SmokeSolver& s = fromInner ? *mInner : full;
  const glm::ivec3 offset = fromInner ? mBox.lo : glm::ivec3(0);
  const glm::ivec3 n = p.resolution;
  const float t = p.adaptiveThreshold;
  ActiveBox box = uniteActive(ActiveBox{}, s.density(), 0.f, t, offset);
  box = uniteActive(box, s.temperature(), p.ambientTemperature, t, offset);
  if (p.combustion) {
    box = uniteActive(box, s.fuel(), 0.f, t, offset);
    box = uniteActive(box, s.soot(), 0.f, t, offset);
  }
  // What the emitters fill this frame, and the obstacles that push the air.
  for (const SmokeSolver::Source& src : full.mSources)
    box = box.united(boxOfCells(src.cells, n, false));
  for (const SmokeSolver::Obstacle& o : full.mObstacles)
    box = box.united(boxOfCells(o.cells, n, true));
  const float h = p.cellSize;
  for (const PointEmitter& e : full.mPointEmitters) {
    // The cells emitPoints() visits (point_emitters.cpp).
    const glm::vec3 c = (e.position - p.origin) / h;
    const float rc = std::max(e.radius, h) / h;
    box = box.withCells(glm::ivec3(glm::floor(c - rc - 0.5f)), glm::ivec3(glm::ceil(c + rc - 0.5f)),
                        n);
  }
  // Nothing to simulate: a box of one block at the domain's corner keeps the solver well-formed.
  if (box.empty()) box = ActiveBox{glm::ivec3(0), glm::ivec3(1)};
  return padBox(box, p.adaptiveMargin, n);
}

void AdaptiveDomain::beginFrame(SmokeSolver& full) {
  const ActiveBox box = boxFor(full, false);
  resetOutside(full, box);
  if (!mInner || box != mBox) mInner = std::make_unique<SmokeSolver>(boxParams(full.params(), box));
  mBox = box;
  setEmitters(full);
  copyIn(full);
}

void AdaptiveDomain::step(SmokeSolver& full, float dt) {
  const ActiveBox box = boxFor(full, true);
  if (box != mBox) {
    syncBack(full);
    resetOutside(full, box);
    mInner = std::make_unique<SmokeSolver>(boxParams(full.params(), box));
    mBox = box;
    setEmitters(full);
    copyIn(full);
  }
  mInner->mTime = full.mTime;  // the sources' noise follows the full solver's clock
  mInner->step(dt);
}

void AdaptiveDomain::setEmitters(const SmokeSolver& full) {
  SmokeSolver& in = *mInner;
  const glm::ivec3 n = full.params().resolution;
  in.clearEmitters();
  for (const SmokeSolver::Source& src : full.mSources)
    in.addSource(cropCells(src.cells, n, mBox), src.settings);
  for (const SmokeSolver::Obstacle& o : full.mObstacles)
    in.addObstacle(cropCells(o.cells, n, mBox), o.slip);
  // Validated by the full solver already (and the box holds every emitter's sphere).
  in.mPointEmitters = full.mPointEmitters;
  if (full.mWindField.count() == 0) {
    in.setWindField(VectorGrid());
  } else {
    VectorGrid wind(mBox.size());
    copyToBox(full.mWindField, wind, mBox.lo);
    in.setWindField(wind);
  }
}

namespace {

template <typename Fn>
void forEachStateGrid(SmokeSolver& a, const SmokeSolver& b, Fn fn) {
  for (int c = 0; c < 3; ++c) fn(a.velocity().component(c), b.velocity().component(c));
  fn(a.density(), b.density());
  fn(a.temperature(), b.temperature());
  fn(a.fuel(), b.fuel());
  fn(a.soot(), b.soot());
  fn(a.flame(), b.flame());
  fn(a.pressure(), b.pressure());
}

}  // namespace

void AdaptiveDomain::copyIn(const SmokeSolver& full) {
  const glm::ivec3 lo = mBox.lo;
  forEachStateGrid(*mInner, full,
                   [&](ScalarGrid& box, const ScalarGrid& f) { copyToBox(f, box, lo); });
}

void AdaptiveDomain::syncBack(SmokeSolver& full) const {
  const glm::ivec3 lo = mBox.lo;
  forEachStateGrid(full, *mInner,
                   [&](ScalarGrid& f, const ScalarGrid& box) { copyFromBox(box, f, lo); });
}

void AdaptiveDomain::resetOutside(SmokeSolver& full, const ActiveBox& box) const {
  const SmokeParams& p = full.params();
  const glm::ivec3 n = p.resolution;
  const bool windy = p.windStrength > 0.f;
  const bool windField = windy && full.mWindField.count() != 0;
  for (int a = 0; a < 3; ++a) {
    ScalarGrid& comp = full.velocity().component(a);
    glm::ivec3 faces = box.size();
    faces[a] += 1;
    fillLeftBehind(comp, glm::ivec3(0), comp.size(), box.lo, faces,
                   windy && !windField ? p.wind[a] : 0.f,
                   windField ? &full.mWindFaces.component(a) : nullptr);
  }
  fillLeftBehind(full.temperature(), glm::ivec3(0), n, box.lo, box.size(), p.ambientTemperature);
  for (ScalarGrid* g :
       {&full.density(), &full.fuel(), &full.soot(), &full.flame(), &full.pressure()})
    fillLeftBehind(*g, glm::ivec3(0), n, box.lo, box.size(), 0.f);
}

}  // namespace plume
