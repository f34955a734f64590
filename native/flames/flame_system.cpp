/// \file flame_system.cpp
/// FlameSystem::step() as named stages (§4.1–4.3, §6.1–6.2).

#include "flames/flame_system.h"

#include "core/parallel.h"
#include "flames/evolution.h"
#include "flames/spine.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {

FlameSystem::FlameSystem(const FlameParams& params, std::uint64_t seed) : mParams(params), mSeed(seed) {
  mParams.validate();
  mSpineNoise = std::make_shared<SpineNoise>(mParams.spineNoise, mSeed);
}

int FlameSystem::addSource(const FlameSource& source) {
  source.validate(int(mSources.size()));
  mSources.push_back(source);
  mLastPosition.push_back(source.position);
  mDisplacement.push_back(glm::dvec3(0.0));
  return int(mSources.size()) - 1;
}

void FlameSystem::setSource(int index, const FlameSource& source) {
  if (index < 0 || index >= int(mSources.size()))
    throw std::invalid_argument("source index must be in [0, " + std::to_string(mSources.size()) + ") (got " +
                                std::to_string(index) + ")");
  source.validate(index);
  mSources[std::size_t(index)] = source;
}

void FlameSystem::setParams(const FlameParams& params) {
  params.validate();
  if (params.spineNoise != mParams.spineNoise)
    mSpineNoise = std::make_shared<SpineNoise>(params.spineNoise, mSeed, *mSpineNoise);
  mParams = params;
}

FlameHeights FlameSystem::heights(const Flame& flame) const {
  const double scale = mSources[std::size_t(flame.source)].heightScale;
  return {mParams.heightPersistent * scale, mParams.heightIntermittent * scale, mParams.heightMax * scale};
}

void FlameSystem::appendFlame(Flame flame) {
  flame.id = mNextId++;
  FlameState state{Rng(mSeed, flame.id), 0.0};
  state.budget = drawWaitingTime(mParams.frequency(flame.radius), state.rng);
  mFlames.push_back(std::move(flame));
  mStates.push_back(state);
}

void FlameSystem::startFlame(int source) {
  const FlameSource& s = mSources[std::size_t(source)];
  Flame f;
  f.source = source;
  f.radius = s.scaledRadius();
  f.intensity = s.intensity;
  f.temperature = s.temperature;
  f.brightness = s.brightness;
  // §4.1: "a particle is generated at a fixed point on the burning surface and released into a
  // wind field"; the step that follows advances it and adds the next one at the surface.
  // Released where the source was at the start of this step: the step then carries it with the
  // source's displacement like every point of an attached flame.
  f.points.resize(1);
  f.points[0].x = s.position - mDisplacement[std::size_t(source)];
  appendFlame(std::move(f));
}

void FlameSystem::updateSources() {
  std::vector<int> attached(mSources.size(), -1);
  for (std::size_t k = 0; k < mFlames.size(); ++k)
    if (!mFlames[k].separated) attached[std::size_t(mFlames[k].source)] = int(k);
  for (std::size_t i = 0; i < mSources.size(); ++i) {
    const FlameSource& s = mSources[i];
    mDisplacement[i] = s.position - mLastPosition[i];
    mLastPosition[i] = s.position;
    const bool active = s.activeAt(mTime);
    if (attached[i] >= 0 && !active) {
      // Burning ended (§6.2 duration maps): the flame leaves the surface and fades like a piece.
      Flame& f = mFlames[std::size_t(attached[i])];
      f.separated = true;
      f.age = 0.0;
      f.lifespan = drawLifespan(mParams.lifespanScale, mStates[std::size_t(attached[i])].rng);
      ++mStats.separatedBorn;
    } else if (attached[i] < 0 && active) {
      startFlame(int(i));
    } else if (attached[i] >= 0) {
      // Spread maps may animate these.
      Flame& f = mFlames[std::size_t(attached[i])];
      f.radius = s.scaledRadius();
      f.intensity = s.intensity;
      f.temperature = s.temperature;
      f.brightness = s.brightness;
    }
  }
}

void FlameSystem::processFlame(std::size_t index, double dt, FlameOutcome& out) {
  Flame& flame = mFlames[index];
  FlameState& state = mStates[index];
  const bool attached = !flame.separated;
  const FlameSource& source = mSources[std::size_t(flame.source)];

  EvolutionInput in;
  in.wind = mWind.size() > 0 ? &mWind : nullptr;
  in.noise = mSpineNoise.get();
  in.time = mTime;
  in.dt = dt;
  in.temperature = flame.temperature;
  glm::dvec3 carried(0.0);
  if (attached) {
    // §4.2: "If the fire-generating surface has a velocity V, the particle P_0 is given an initial
    // velocity −V. The flame is then generated in a stationary reference frame." Read as: an
    // attached flame is kept in its source's frame (rigidly carried by the source's
    // displacement), where the air, hence every particle released into it, moves at −V; a torch
    // moving at V thus trails its flame. Source motion given only by V (a still dragon's mouth
    // "with an initial velocity") throws the flame at −V.
    carried = mDisplacement[std::size_t(flame.source)];
    for (SpinePoint& p : flame.points) p.x += carried;
    in.sourceTerm = -source.velocity;
  }
  evolvePoints(flame.points, mParams, in, state.rng);

  // Fit and re-sample (§4.1). An attached flame gets the new particle at the surface first.
  const glm::dvec3 carriedVelocity = carried / dt;
  if (attached) {
    SpinePoint base;
    base.x = source.position;
    base.v = driftVelocity(mParams, in.wind, base.x, mTime + dt, 0.0, flame.temperature, in.sourceTerm, in.noise);
    flame.points.insert(flame.points.begin(), base);
    for (SpinePoint& p : flame.points) p.v += carriedVelocity;  // world-frame dx/dt
  }
  const int count = attached ? mParams.points : int(flame.points.size());
  const Spine spine = Spine::fit(flame.points);
  flame.points = resampleSpine(spine, flame.points, 0.0, spine.length(), count);

  // Breakaway (§4.3).
  if (attached || mParams.separatedCanSplit) {
    out.decision = testBreakaway(spine.length(), heights(flame), mParams.frequency(flame.radius), dt,
                                 state.budget, state.rng);
    if (out.decision.split) {
      std::vector<SpinePoint> lower, upper;
      splitSpine(flame.points, out.decision.height, attached ? mParams.points : 0, lower, upper);
      flame.points = std::move(lower);
      out.hasPiece = true;
      out.piece = flame;  // radius, intensity, temperature, source
      out.piece.points = std::move(upper);
      out.piece.separated = true;
      out.piece.splitLength = spine.length();
      out.piece.age = 0.0;
      out.pieceLifespan = drawLifespan(mParams.lifespanScale, state.rng);
    }
  }

  // Obstacles (§6.1): the fallback direction is towards the previous (base-side) point, which is
  // outside when the spine enters an obstacle from the free side.
  if (!mObstacles.empty()) {
    auto push = [&](std::vector<SpinePoint>& pts, int first) {
      for (int k = first; k < int(pts.size()); ++k) {
        const glm::dvec3 towards = k > 0 ? pts[std::size_t(k) - 1].x - pts[std::size_t(k)].x : glm::dvec3(0.0);
        mObstacles.pushOut(pts[std::size_t(k)].x, mParams.obstacleMargin, towards);
      }
    };
    push(flame.points, attached ? 1 : 0);
    if (out.hasPiece) push(out.piece.points, 0);
  }
  flame.age += dt;
}

void FlameSystem::mergeOutcomes(std::vector<FlameOutcome>& outcomes, double dt) {
  std::vector<Flame> pieces;
  std::vector<double> lifespans;
  for (FlameOutcome& o : outcomes) {
    if (o.decision.eligible) mStats.eligibleTime += dt;
    if (o.decision.split) ++(o.decision.forced ? mStats.forcedBreakaways : mStats.breakaways);
    if (o.hasPiece) {
      pieces.push_back(std::move(o.piece));
      lifespans.push_back(o.pieceLifespan);
    }
  }
  // Remove separated flames at the end of their life (age is counted from the step they appeared).
  std::size_t kept = 0;
  for (std::size_t k = 0; k < mFlames.size(); ++k) {
    const Flame& f = mFlames[k];
    if (f.separated && f.age >= f.lifespan) {
      ++mStats.separatedDied;
      mStats.lifespanSum += f.lifespan;
      mStats.ageAtDeathSum += f.age;
      continue;
    }
    if (kept != k) {
      mFlames[kept] = std::move(mFlames[k]);
      mStates[kept] = mStates[k];
    }
    ++kept;
  }
  mFlames.resize(kept);
  mStates.erase(mStates.begin() + std::ptrdiff_t(kept), mStates.end());
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    pieces[p].lifespan = lifespans[p];
    appendFlame(std::move(pieces[p]));
    ++mStats.separatedBorn;
  }
}

void FlameSystem::step(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw std::invalid_argument("dt must be a finite number > 0 s (got " + std::to_string(dt) + ")");
  updateSources();
  std::vector<FlameOutcome> outcomes(mFlames.size());
  parallelFor(0, int(mFlames.size()), [&](int k) { processFlame(std::size_t(k), dt, outcomes[std::size_t(k)]); });
  mergeOutcomes(outcomes, dt);
  mTime += dt;
}

}  // namespace plume
