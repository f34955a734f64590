/// \file toon_particles.cpp
/// Toon particle evolution (cartoon_smoke.txt §2.1-2.3); the stages are listed in the header.

#include "toon/toon_particles.h"

#include "core/parallel.h"
#include "core/rng.h"
#include "toon/field_sampler.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace plume {
namespace {

/// Particles per parallel task: enough work to pay for the task, small enough to balance.
constexpr int kChunk = 512;

/// Random streams of the two stages that create particles.
enum class Stream : std::uint64_t { Emission = 1, Birth = 2 };

/// The generator of one emission or birth: a seed per (frame, stage), a stream per index, so a
/// particle's position does not depend on which thread creates it or on the other particles.
Rng streamRng(std::uint64_t seed, std::int64_t frame, Stream stage, std::uint64_t index) {
  const std::uint64_t key = std::uint64_t(frame) * 0x9E3779B97F4A7C15ull +
                            std::uint64_t(stage) * 0xC2B2AE3D27D4EB4Full;
  return Rng(seed ^ key, index);
}

/// A random point of the unit cube, kept 1e-3 away from its faces so that rounding never moves a
/// particle born in a cell into its neighbour (birth counts the particles per cell).
glm::vec3 uniform3(Rng& r) {
  constexpr double kMargin = 1e-3;
  auto u = [&] { return float(kMargin + (1.0 - 2.0 * kMargin) * r.uniform()); };
  const float x = u(), y = u(), z = u();
  return {x, y, z};
}

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// Particle indices [first, count), or order[first, count) when `order` is given, in parallel
/// chunks of kChunk, handed to body(index, lanes) four at a time (field_sampler.h): `lanes`
/// (1 to 4) are valid, the others repeat the last valid index.
template <typename Body>
void forGroups(const std::vector<std::uint32_t>* order, std::size_t first, std::size_t count,
               const Body& body) {
  if (count <= first) return;
  const std::size_t n = count - first;
  parallelFor(0, int((n + kChunk - 1) / kChunk), [&](int c) {
    const std::size_t b = first + std::size_t(c) * kChunk;
    const std::size_t e = std::min(count, b + kChunk);
    for (std::size_t m = b; m < e; m += 4) {
      const int lanes = int(std::min<std::size_t>(4, e - m));
      std::size_t index[4];
      for (int l = 0; l < 4; ++l) {
        const std::size_t k = m + std::size_t(std::min(l, lanes - 1));
        index[l] = order ? std::size_t((*order)[k]) : k;
      }
      body(index, lanes);
    }
  });
}

}  // namespace

void ToonParticleState::resize(std::size_t n) {
  ids.resize(n);
  positions.resize(n);
  velocities.resize(n);
  density.resize(n);
  temperature.resize(n);
  size.resize(n);
  targetSize.resize(n);
  color.resize(n);
  age.resize(n);
}

void ToonParticleState::validate() const {
  const std::size_t n = ids.size();
  if (positions.size() != n || velocities.size() != n || density.size() != n ||
      temperature.size() != n || size.size() != n || targetSize.size() != n || color.size() != n ||
      age.size() != n)
    throw std::invalid_argument("toon particles: every array must hold " + std::to_string(n) +
                                " entries (one per id)");
  if (frame < 0) throw std::invalid_argument("toon particles: frame must be >= 0");
  for (std::size_t m = 0; m < n; ++m) {
    if (ids[m] >= nextId || (m > 0 && ids[m] <= ids[m - 1]))
      throw std::invalid_argument("toon particles: ids must ascend and stay below next_id (" +
                                  std::to_string(nextId) + ")");
    if (!finite(positions[m]) || !finite(velocities[m]) || !std::isfinite(density[m]) ||
        !std::isfinite(temperature[m]) || !(size[m] >= 0.f) || !std::isfinite(size[m]) ||
        !(targetSize[m] >= 0.f) || !std::isfinite(targetSize[m]) || !(color[m] >= 0.f) ||
        !(color[m] <= 1.f) || age[m] < 0)
      throw std::invalid_argument("toon particles: particle " + std::to_string(m) +
                                  " has a non-finite or out-of-range value");
  }
}

ToonParticles::ToonParticles(const ToonParams& params, const GridFrame& grid)
    : mParams(params), mGrid(grid) {
  mParams.validate();
  validateToonGrid(grid);
  mInvCellSize = 1.f / grid.cellSize;
  mHi = grid.origin + glm::vec3(grid.resolution) * grid.cellSize;
}

void ToonParticles::setState(ToonParticleState state) {
  state.validate();
  if (state.count() > std::size_t(mParams.maxCount))
    throw std::invalid_argument("toon particles: " + std::to_string(state.count()) +
                                " particles exceed max_count (" +
                                std::to_string(mParams.maxCount) + ")");
  mState = std::move(state);
}

int ToonParticles::substeps(const ToonFields& before, const ToonFields& after, float dt) const {
  if (!(dt > 0.f) || !std::isfinite(dt))
    throw std::invalid_argument("dt must be a finite number > 0 seconds (got " +
                                std::to_string(dt) + ")");
  before.validate(mGrid.resolution, "frame-start");
  after.validate(mGrid.resolution, "frame-end");
  const double cells = double(std::max(before.maxSpeed(), after.maxSpeed())) * double(dt) *
                       double(mInvCellSize);
  const double n = std::ceil(cells / double(mParams.cfl));
  if (!(n <= double(kMaxToonSubsteps)))
    throw std::runtime_error("toon particles: a speed of " + std::to_string(cells) +
                             " cells per frame would need more than " +
                             std::to_string(kMaxToonSubsteps) + " substeps (a broken cache?)");
  return std::max(1, int(n));
}

int ToonParticles::advanceFrame(const ToonFields& before, const ToonFields& after, float dt,
                                const ToonSources& sources) {
  const int n = substeps(before, after, dt);  // every check happens before anything changes
  sources.validate(mGrid);
  ThreadLimit limit(mParams.threads);
  sortByRow();
  advect(before, after, dt, n);
  sample(after, 0, /*resize=*/true);
  for (std::int32_t& a : mState.age) ++a;
  removeDead();
  const std::size_t first = mState.count();
  emit(sources);
  birth(after);
  sample(after, first, /*resize=*/false);  // newborns start at size 0 (§2.3)
  ++mState.frame;
  return n;
}

void ToonParticles::sortByRow() {
  // Counting sort on the row index j + ny k (one more bin for particles outside the grid).
  const glm::ivec3 n = mGrid.resolution;
  const std::uint32_t rows = std::uint32_t(n.y) * std::uint32_t(n.z);
  const std::size_t count = mState.count();
  auto row = [&](glm::vec3 x) {
    const glm::vec3 c = glm::floor((x - mGrid.origin) * mInvCellSize);
    if (!(c.y >= 0.f && c.z >= 0.f && c.y < float(n.y) && c.z < float(n.z))) return rows;
    return std::uint32_t(c.y) + std::uint32_t(n.y) * std::uint32_t(c.z);
  };
  mRowStart.assign(std::size_t(rows) + 2, 0);
  for (const glm::vec3& x : mState.positions) ++mRowStart[std::size_t(row(x)) + 1];
  for (std::size_t r = 1; r < mRowStart.size(); ++r) mRowStart[r] += mRowStart[r - 1];
  mOrder.resize(count);
  for (std::size_t m = 0; m < count; ++m)
    mOrder[mRowStart[row(mState.positions[m])]++] = std::uint32_t(m);
}

void ToonParticles::advect(const ToonFields& a, const ToonFields& b, float dt, int substeps) {
  const float h = dt / float(substeps);
  const bool midpoint = mParams.integration == ToonIntegration::Midpoint;
  const glm::ivec3 n = mGrid.resolution;
  // Velocity linear in time between the frame's end fields (t in [0, 1] over the frame).
  auto velocity = [&](const glm::vec3* x, float t, glm::vec3* v) {
    glm::vec3 c[4];
    for (int l = 0; l < 4; ++l) c[l] = toCell(x[l]);
    const PositionSplits4 s(n, c);
    if (t <= 0.f || t >= 1.f) return sampleFaces4(t <= 0.f ? a.velocity : b.velocity, s, v);
    glm::vec3 va[4], vb[4];
    sampleFaces4(a.velocity, s, va);
    sampleFaces4(b.velocity, s, vb);
    for (int l = 0; l < 4; ++l) v[l] = (1.f - t) * va[l] + t * vb[l];
  };
  const float inv = 1.f / float(substeps);
  forGroups(&mOrder, 0, mState.count(), [&](const std::size_t* index, int lanes) {
    glm::vec3 x[4], v[4];
    for (int l = 0; l < 4; ++l) x[l] = mState.positions[index[l]];
    for (int s = 0; s < substeps; ++s) {
      const float t = float(s) * inv;
      velocity(x, t, v);
      if (midpoint) {
        glm::vec3 xm[4];
        for (int l = 0; l < 4; ++l) xm[l] = x[l] + (0.5f * h) * v[l];
        velocity(xm, (float(s) + 0.5f) * inv, v);
      }
      for (int l = 0; l < 4; ++l) x[l] += h * v[l];  // §2.1: Euler integration (or midpoint)
    }
    for (int l = 0; l < lanes; ++l)
      if (finite(x[l])) mState.positions[index[l]] = x[l];  // a broken field must not poison the cache
  });
}

void ToonParticles::sample(const ToonFields& b, std::size_t first, bool resize) {
  const float step = mParams.maxSizeStep();
  const bool hasTemperature = b.temperature.count() != 0;
  ToonParticleState& s = mState;
  // Resizing (the particles of the frame start): in row order, as advect(), since they moved at
  // most a few cells; newborns are created in cell order already.
  forGroups(resize ? &mOrder : nullptr, first, s.count(), [&](const std::size_t* index, int lanes) {
    glm::vec3 c[4], v[4];
    for (int l = 0; l < 4; ++l) c[l] = toCell(s.positions[index[l]]);
    const PositionSplits4 splits(mGrid.resolution, c);
    float d[4], temp[4] = {0.f, 0.f, 0.f, 0.f};
    sampleFaces4(b.velocity, splits, v);
    sampleCentred4(b.density, splits, d);
    if (hasTemperature) sampleCentred4(b.temperature, splits, temp);
    for (int l = 0; l < lanes; ++l) {
      const std::size_t m = index[l];
      // No smoke is simulated outside the domain: the particle fades out there.
      const float density = insideBox(s.positions[m]) && std::isfinite(d[l]) ? d[l] : 0.f;
      const float target = density < mParams.deathDensity ? 0.f : mParams.rampSize(density);
      s.velocities[m] = finite(v[l]) ? v[l] : glm::vec3(0.f);
      s.density[m] = density;
      s.temperature[m] = std::isfinite(temp[l]) ? temp[l] : 0.f;
      s.targetSize[m] = std::isfinite(target) ? target : 0.f;
      s.color[m] = mParams.colorParameter(density, s.temperature[m], glm::length(s.velocities[m]));
      if (resize) {
        // §2.3 temporal coherence: at most `step` per frame toward the ramp's size.
        const float size = s.size[m], diff = s.targetSize[m] - size;
        s.size[m] = std::abs(diff) <= step ? s.targetSize[m] : (diff > 0.f ? size + step : size - step);
      }
    }
  });
}

void ToonParticles::removeDead() {
  ToonParticleState& s = mState;
  std::size_t out = 0;
  for (std::size_t m = 0; m < s.count(); ++m) {
    // Dying (below ρ_death) and already shrunk to nothing: removing it changes no pixel.
    if (s.size[m] <= 0.f && s.density[m] < mParams.deathDensity) continue;
    if (out != m) {
      s.ids[out] = s.ids[m];
      s.positions[out] = s.positions[m];
      s.velocities[out] = s.velocities[m];
      s.density[out] = s.density[m];
      s.temperature[out] = s.temperature[m];
      s.size[out] = s.size[m];
      s.targetSize[out] = s.targetSize[m];
      s.color[out] = s.color[m];
      s.age[out] = s.age[m];
    }
    ++out;
  }
  s.resize(out);
}

void ToonParticles::append(glm::vec3 p) {
  const std::size_t m = mState.count();
  mState.resize(m + 1);
  mState.ids[m] = mState.nextId++;
  mState.positions[m] = p;
  mState.velocities[m] = glm::vec3(0.f);
  mState.density[m] = mState.temperature[m] = mState.size[m] = 0.f;
  mState.targetSize[m] = mState.color[m] = 0.f;
  mState.age[m] = 0;
}

void ToonParticles::emit(const ToonSources& sources) {
  const std::uint64_t entries = sources.size(), count = std::uint64_t(mParams.emissionCount);
  if (entries == 0) return;
  for (std::uint64_t e = 0; e < count && mState.count() < std::size_t(mParams.maxCount); ++e) {
    // Entries in turn across frames, so every source cell emits over time.
    const std::uint64_t entry = (std::uint64_t(mState.frame) * count + e) % entries;
    Rng rng = streamRng(mParams.seed, mState.frame, Stream::Emission, e);
    const glm::vec3 u = uniform3(rng);
    glm::vec3 p;
    if (entry < sources.cells.size()) {
      p = mGrid.origin + (glm::vec3(sources.cells[entry]) + u) * mGrid.cellSize;
    } else {
      // Jittered over one cell around the point: particles emitted together at one point would
      // otherwise follow the same path forever.
      p = sources.points[entry - sources.cells.size()] + (u - 0.5f) * mGrid.cellSize;
      p = glm::clamp(p, mGrid.origin, mHi);
    }
    append(p);
  }
}

void ToonParticles::birth(const ToonFields& b) {
  const glm::ivec3 n = mGrid.resolution;
  const std::size_t slab = std::size_t(n.x) * std::size_t(n.y);
  mOccupied.assign(slab * std::size_t(n.z), 0);
  for (const glm::vec3& x : mState.positions) {
    if (!insideBox(x)) continue;
    const glm::ivec3 c = glm::clamp(glm::ivec3(glm::floor((x - mGrid.origin) * mInvCellSize)),
                                    glm::ivec3(0), n - 1);
    mOccupied[b.density.index(c.x, c.y, c.z)] = 1;
  }
  const float threshold = mParams.birthDensity;
  auto wanted = [&](std::size_t m) { return b.density[m] > threshold && !mOccupied[m]; };
  // Pass 1: empty dense cells per slab; pass 2 fills them in cell order from each slab's offset.
  std::vector<std::size_t> offset(std::size_t(n.z) + 1, 0);
  parallelFor(0, n.z, [&](int k) {
    std::size_t c = 0;
    for (std::size_t m = std::size_t(k) * slab, e = m + slab; m < e; ++m) c += wanted(m);
    offset[std::size_t(k) + 1] = c;
  });
  for (int k = 0; k < n.z; ++k) offset[std::size_t(k) + 1] += offset[std::size_t(k)];
  const std::size_t room = std::size_t(mParams.maxCount) - std::min(mState.count(), std::size_t(mParams.maxCount));
  const std::size_t births = std::min(offset.back(), room);
  if (births == 0) return;
  const std::size_t first = mState.count();
  const std::uint64_t firstId = mState.nextId;
  mState.resize(first + births);
  parallelFor(0, n.z, [&](int k) {
    std::size_t rank = offset[std::size_t(k)];
    for (int j = 0; j < n.y && rank < births; ++j)
      for (int i = 0; i < n.x && rank < births; ++i) {
        const std::size_t m = b.density.index(i, j, k);
        if (!wanted(m)) continue;
        Rng rng = streamRng(mParams.seed, mState.frame, Stream::Birth, m);
        const std::size_t p = first + rank;
        mState.ids[p] = firstId + rank;
        mState.positions[p] = mGrid.origin + (glm::vec3(i, j, k) + uniform3(rng)) * mGrid.cellSize;
        mState.velocities[p] = glm::vec3(0.f);
        mState.density[p] = mState.temperature[p] = mState.size[p] = 0.f;
        mState.targetSize[p] = mState.color[p] = 0.f;
        mState.age[p] = 0;
        ++rank;
      }
  });
  mState.nextId += births;
}

}  // namespace plume
