/// \file toon_particles.cpp
/// Toon particle evolution ([Cartoon Smoke] §2.1-2.3); the stages are listed in the header.

#include "toon/toon_particles.h"

#include "core/parallel.h"
#include "core/rng.h"
#include "toon/field_sampler.h"
#include "toon/ramp_lanes.h"
#include "toon/toon_random.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

#include <smmintrin.h>

namespace plume {
namespace {

using toon::Stream;
using toon::streamRng;
using toon::uniform3;

/// Particles per parallel task: enough work to pay for the task, small enough to balance.
constexpr int kChunk = 512;

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// Particles per group (field_sampler.h).
constexpr int kLanes = kToonLanes;

/// Particle indices [first, count), or order[first, count) when `order` is given, in parallel
/// chunks of kChunk, handed to body(index, lanes) kLanes at a time: `lanes` (1 to kLanes) are
/// valid, the others repeat the last valid index.
template <typename Body>
void forGroups(const std::vector<std::uint32_t>* order, std::size_t first, std::size_t count,
               const Body& body) {
  if (count <= first) return;
  const std::size_t n = count - first;
  parallelFor(0, int((n + kChunk - 1) / kChunk), [&](int c) {
    const std::size_t b = first + std::size_t(c) * kChunk;
    const std::size_t e = std::min(count, b + kChunk);
    for (std::size_t m = b; m < e; m += kLanes) {
      const int lanes = int(std::min<std::size_t>(kLanes, e - m));
      std::size_t index[kLanes];
      for (int l = 0; l < kLanes; ++l) {
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
  const ToonFieldSampler sampler(mGrid.resolution);
  sortByRow();
  mOccupied.assign(std::size_t(mGrid.resolution.x) * std::size_t(mGrid.resolution.y) *
                       std::size_t(mGrid.resolution.z), 0);
  advectAndSample(sampler, before, after, dt, n);
  for (std::int32_t& a : mState.age) ++a;
  removeDead();
  const std::size_t emitted = mState.count();
  emit(sources);
  birth(after, emitted);
  // Newborns start at size 0 (§2.3); they are created in cell order already.
  forGroups(nullptr, emitted, mState.count(), [&](const std::size_t* index, int lanes) {
    ToonLanes3 x;
    gather(index, x);
    sampleGroup(sampler, after, index, lanes, x, /*resize=*/false);
  });
  ++mState.frame;
  return n;
}

void ToonParticles::sortByRow() {
  // Counting sort on the row index j + ny k (one more bin for particles outside the grid).
  const glm::ivec3 n = mGrid.resolution;
  const std::uint32_t rows = std::uint32_t(n.y) * std::uint32_t(n.z);
  const std::size_t count = mState.count();
  mRow.resize(count);
  mRowStart.assign(std::size_t(rows) + 2, 0);
  for (std::size_t m = 0; m < count; ++m) {
    const glm::vec3& x = mState.positions[m];
    const float cy = std::floor((x.y - mGrid.origin.y) * mInvCellSize);
    const float cz = std::floor((x.z - mGrid.origin.z) * mInvCellSize);
    const bool inside = (cy >= 0.f) & (cz >= 0.f) & (cy < float(n.y)) & (cz < float(n.z));
    mRow[m] = inside ? std::uint32_t(cy) + std::uint32_t(n.y) * std::uint32_t(cz) : rows;
    ++mRowStart[std::size_t(mRow[m]) + 1];
  }
  for (std::size_t r = 1; r < mRowStart.size(); ++r) mRowStart[r] += mRowStart[r - 1];
  mOrder.resize(count);
  for (std::size_t m = 0; m < count; ++m) mOrder[mRowStart[mRow[m]]++] = std::uint32_t(m);
}

void ToonParticles::advectAndSample(const ToonFieldSampler& sampler, const ToonFields& a,
                                    const ToonFields& b, float dt, int substeps) {
  const float h = dt / float(substeps), inv = 1.f / float(substeps);
  const bool midpoint = mParams.integration == ToonIntegration::Midpoint;
  forGroups(&mOrder, 0, mState.count(), [&](const std::size_t* index, int lanes) {
    ToonLanes3 x, v;
    // Velocity linear in time between the frame's end fields (t in [0, 1] over the frame).
    auto velocity = [&](const ToonLanes3& p, float t) {
      ToonLanes3 c;
      toCells(p, c);
      sampler.velocity(a.velocity, b.velocity, t, c, v);
    };
    // x + w v into y, lane by lane (the glm form x + w * v, component by component).
    auto step = [&](const ToonLanes3& p, float w, ToonLanes3& y) {
      for (int c = 0; c < 3; ++c)
        for (int l = 0; l < kLanes; ++l) y.c[c][l] = p.c[c][l] + w * v.c[c][l];
    };
    gather(index, x);
    for (int s = 0; s < substeps; ++s) {
      velocity(x, float(s) * inv);
      if (midpoint) {
        ToonLanes3 xm;
        step(x, 0.5f * h, xm);
        velocity(xm, (float(s) + 0.5f) * inv);
      }
      step(x, h, x);  // §2.1: Euler integration (or midpoint)
    }
    int finiteLane = 0;  // bit l: lane l is finite
    for (int half = 0; half < kLanes; half += 4) {
      __m128 f = finiteLanes(_mm_load_ps(x.c[0] + half));
      for (int c = 1; c < 3; ++c) f = _mm_and_ps(f, finiteLanes(_mm_load_ps(x.c[c] + half)));
      finiteLane |= _mm_movemask_ps(f) << half;
    }
    for (int l = 0; l < kLanes; ++l) {
      // A broken field must not poison the cache: the particle stays where it was.
      glm::vec3& p = mState.positions[index[std::min(l, lanes - 1)]];
      if (!((finiteLane >> l) & 1))
        for (int c = 0; c < 3; ++c) x.c[c][l] = p[c];
      else if (l < lanes)
        p = glm::vec3(x.c[0][l], x.c[1][l], x.c[2][l]);
    }
    sampleGroup(sampler, b, index, lanes, x, /*resize=*/true);
  });
}

void ToonParticles::sampleGroup(const ToonFieldSampler& sampler, const ToonFields& b,
                                const std::size_t* index, int lanes, const ToonLanes3& x,
                                bool resize) {
  ToonParticleState& s = mState;
  ToonLanes3 c, v;
  alignas(32) float d[kLanes], temp[kLanes], size[kLanes], target[kLanes], color[kLanes];
  alignas(32) int cell[3][kLanes];
  alignas(32) std::uint8_t mark[kLanes];
  toCells(x, c);
  sampler.fields(b, c, v, d, temp);
  for (int l = 0; l < kLanes; ++l) size[l] = s.size[index[l]];
  const RampLanes4 ramps(mParams);
  const __m128 death = _mm_set1_ps(mParams.deathDensity);
  for (int h = 0; h < kLanes; h += 4) {
    __m128 p[3], inside = _mm_castsi128_ps(_mm_set1_epi32(-1));
    for (int a = 0; a < 3; ++a) {
      p[a] = _mm_load_ps(x.c[a] + h);
      inside = _mm_and_ps(inside, _mm_and_ps(_mm_cmpge_ps(p[a], _mm_set1_ps(mGrid.origin[a])),
                                             _mm_cmple_ps(p[a], _mm_set1_ps(mHi[a]))));
    }
    // No smoke is simulated outside the domain: the particle fades out there.
    __m128 density = _mm_load_ps(d + h);
    density = _mm_and_ps(_mm_and_ps(inside, finiteLanes(density)), density);
    __m128 vel[3], finiteVelocity = finiteLanes(_mm_load_ps(v.c[0] + h));
    for (int a = 1; a < 3; ++a)
      finiteVelocity = _mm_and_ps(finiteVelocity, finiteLanes(_mm_load_ps(v.c[a] + h)));
    for (int a = 0; a < 3; ++a) {
      vel[a] = _mm_and_ps(finiteVelocity, _mm_load_ps(v.c[a] + h));
      _mm_store_ps(v.c[a] + h, vel[a]);
    }
    __m128 temperature = _mm_load_ps(temp + h);
    temperature = _mm_and_ps(finiteLanes(temperature), temperature);
    const __m128 goal = ramps.targetSize(density);
    const __m128 grown = ramps.sizeStep(_mm_load_ps(size + h), goal);
    _mm_store_ps(d + h, density);
    _mm_store_ps(temp + h, temperature);
    _mm_store_ps(target + h, goal);
    _mm_store_ps(size + h, grown);
    _mm_store_ps(color + h, ramps.color(density, temperature, vel));
    // Stage 5's occupancy: a survivor of removeDead() (not shrunk to 0 below ρ_death) inside the
    // box marks its cell floor((x - origin) / cell size), clamped into the grid.
    const __m128 dead =
        _mm_and_ps(_mm_cmple_ps(grown, _mm_setzero_ps()), _mm_cmplt_ps(density, death));
    const int marked = _mm_movemask_ps(_mm_andnot_ps(dead, inside));
    for (int l = 0; l < 4; ++l) mark[h + l] = std::uint8_t((marked >> l) & 1);
    for (int a = 0; a < 3; ++a) {
      const __m128 f = _mm_floor_ps(
          _mm_mul_ps(_mm_sub_ps(p[a], _mm_set1_ps(mGrid.origin[a])), _mm_set1_ps(mInvCellSize)));
      const __m128i i = _mm_min_epi32(_mm_max_epi32(_mm_cvttps_epi32(f), _mm_setzero_si128()),
                                      _mm_set1_epi32(mGrid.resolution[a] - 1));
      _mm_store_si128(reinterpret_cast<__m128i*>(cell[a] + h), i);
    }
  }
  const std::size_t nx = std::size_t(mGrid.resolution.x), ny = std::size_t(mGrid.resolution.y);
  for (int l = 0; l < lanes; ++l) {
    const std::size_t m = index[l];
    s.velocities[m] = glm::vec3(v.c[0][l], v.c[1][l], v.c[2][l]);
    s.density[m] = d[l];
    s.temperature[m] = temp[l];
    s.targetSize[m] = target[l];
    s.color[m] = color[l];
    if (!resize) continue;
    s.size[m] = size[l];
    // Threads may mark one cell together, hence the atomic store.
    if (mark[l])
      __atomic_store_n(&mOccupied[std::size_t(cell[0][l]) +
                                  nx * (std::size_t(cell[1][l]) + ny * std::size_t(cell[2][l]))],
                       std::uint8_t(1), __ATOMIC_RELAXED);
  }
}

void ToonParticles::removeDead() {
  ToonParticleState& s = mState;
  const std::size_t n = s.count();
  // Dying (below ρ_death) and already shrunk to nothing: removing it changes no pixel.
  auto dead = [&](std::size_t m) {
    return s.size[m] <= 0.f && s.density[m] < mParams.deathDensity;
  };
  // The survivors move down in runs (few particles die per frame), every array in turn.
  std::size_t out = 0, m = 0;
  while (m < n && !dead(m)) ++m;
  out = m;
  while (m < n) {
    while (m < n && dead(m)) ++m;
    const std::size_t begin = m;
    while (m < n && !dead(m)) ++m;
    auto move = [&](auto& v) { std::copy(v.begin() + begin, v.begin() + m, v.begin() + out); };
    move(s.ids);
    move(s.positions);
    move(s.velocities);
    move(s.density);
    move(s.temperature);
    move(s.size);
    move(s.targetSize);
    move(s.color);
    move(s.age);
    out += m - begin;
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
  // Stratified over the entries (every source's cells in turn): each frame's particles spread
  // over all sources, and a per-frame offset makes every cell emit over time. (Entries taken in
  // turn across frames emitted a short burst from the first source's first cells only.)
  Rng offsetRng = streamRng(mParams.seed, mState.frame, Stream::EmissionOffset, 0);
  const double offset = offsetRng.uniform();
  for (std::uint64_t e = 0; e < count && mState.count() < std::size_t(mParams.maxCount); ++e) {
    const std::uint64_t entry = std::min<std::uint64_t>(
        entries - 1, std::uint64_t((double(e) + offset) * double(entries) / double(count)));
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

void ToonParticles::birth(const ToonFields& b, std::size_t emitted) {
  const glm::ivec3 n = mGrid.resolution;
  const std::size_t slab = std::size_t(n.x) * std::size_t(n.y);
  const std::size_t room =
      std::size_t(mParams.maxCount) - std::min(mState.count(), std::size_t(mParams.maxCount));
  if (room == 0) return;  // the budget is spent: nothing to look for
  // The survivors marked their cells in sampleGroup(); the particles just emitted mark theirs.
  for (std::size_t m = emitted; m < mState.count(); ++m)
    if (insideBox(mState.positions[m])) mOccupied[cellIndex(mState.positions[m])] = 1;
  // Pass 1: mWanted[m] = 1 for an empty cell denser than ρ_birth; the count per slab gives each
  // slab's first rank. With a birth spacing, spaceBirths() keeps those far enough from every
  // particle and the slabs are counted again. Pass 2 fills the wanted cells in cell order from
  // that rank.
  const float threshold = mParams.birthDensity;
  const float* density = b.density.data();
  mWanted.resize(mOccupied.size());
  mSlabOffset.assign(std::size_t(n.z) + 1, 0);
  parallelFor(0, n.z, [&](int k) {
    std::size_t c = 0, m = std::size_t(k) * slab;
    const std::size_t e = m + slab;
    const __m128 limit = _mm_set1_ps(threshold);
    for (; m + 16 <= e; m += 16) {  // 16 cells: density > ρ_birth (NaN fails) and no particle
      const __m128i dense = _mm_packs_epi16(
          _mm_packs_epi32(_mm_castps_si128(_mm_cmpgt_ps(_mm_loadu_ps(density + m), limit)),
                          _mm_castps_si128(_mm_cmpgt_ps(_mm_loadu_ps(density + m + 4), limit))),
          _mm_packs_epi32(_mm_castps_si128(_mm_cmpgt_ps(_mm_loadu_ps(density + m + 8), limit)),
                          _mm_castps_si128(_mm_cmpgt_ps(_mm_loadu_ps(density + m + 12), limit))));
      const __m128i empty = _mm_cmpeq_epi8(
          _mm_loadu_si128(reinterpret_cast<const __m128i*>(&mOccupied[m])), _mm_setzero_si128());
      const __m128i w = _mm_and_si128(dense, empty);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(&mWanted[m]), _mm_and_si128(w, _mm_set1_epi8(1)));
      c += std::size_t(__builtin_popcount(unsigned(_mm_movemask_epi8(w))));
    }
    for (; m < e; ++m) {
      const std::uint8_t w = std::uint8_t(density[m] > threshold) & std::uint8_t(mOccupied[m] == 0);
      mWanted[m] = w;
      c += w;
    }
    mSlabOffset[std::size_t(k) + 1] = c;
  });
  if (mParams.birthSpacing > 0.f && std::any_of(mSlabOffset.begin(), mSlabOffset.end(),
                                                [](std::size_t c) { return c > 0; })) {
    spaceBirths(mParams, mGrid, density, mState.positions, mState.frame, mWanted, mSpacing);
    parallelFor(0, n.z, [&](int k) {
      const std::uint8_t* w = mWanted.data() + std::size_t(k) * slab;
      mSlabOffset[std::size_t(k) + 1] = std::size_t(std::count(w, w + slab, std::uint8_t(1)));
    });
  }
  for (int k = 0; k < n.z; ++k) mSlabOffset[std::size_t(k) + 1] += mSlabOffset[std::size_t(k)];
  const std::size_t births = std::min(mSlabOffset.back(), room);
  if (births == 0) return;
  const std::size_t first = mState.count();
  const std::uint64_t firstId = mState.nextId;
  mState.resize(first + births);
  parallelFor(0, n.z, [&](int k) {
    std::size_t rank = mSlabOffset[std::size_t(k)];
    const std::size_t end = std::min(mSlabOffset[std::size_t(k) + 1], births);
    const std::size_t base = std::size_t(k) * slab;
    for (std::size_t r = 0; rank < end; ++r) {
      // Eight cells at a time past the empty ones (most of a slab).
      if (r + 8 <= slab) {
        std::uint64_t word;
        std::memcpy(&word, &mWanted[base + r], 8);
        if (word == 0) {
          r += 7;
          continue;
        }
      }
      if (!mWanted[base + r]) continue;
      const int i = int(r % std::size_t(n.x)), j = int(r / std::size_t(n.x));
      const std::size_t p = first + rank;
      mState.ids[p] = firstId + rank;
      mState.positions[p] = toon::birthPosition(mParams.seed, mState.frame, mGrid, {i, j, k}, base + r);
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
