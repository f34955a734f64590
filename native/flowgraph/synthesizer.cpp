#include "flowgraph/synthesizer.h"

#include "core/parallel.h"
#include "flowgraph/pathline_file.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace plume {
namespace {

/// Particles per parallel task (also the batch of ExternalVelocity::evaluate()).
constexpr int kChunk = 512;

}  // namespace

Synthesizer::Synthesizer(const PathlineLayout& layout, int threads, std::size_t cacheBytes)
    : Synthesizer(layout, threads, std::make_shared<PreparedGroupCache>(cacheBytes)) {}

Synthesizer::Synthesizer(const PathlineLayout& layout, int threads,
                         std::shared_ptr<PreparedGroupCache> cache)
    : mLayout(layout), mThreads(threads), mCache(std::move(cache)) {
  if (!mCache) throw std::invalid_argument("synthesis needs a cache of prepared groups (got none)");
  if (layout.particles < 1)
    throw std::invalid_argument("synthesis needs pathline groups of >= 1 particle (got " +
                                std::to_string(layout.particles) + ")");
  if (layout.samples < 2)
    throw std::invalid_argument("synthesis needs pathlines of >= 2 samples (got " +
                                std::to_string(layout.samples) + ")");
  if (!(layout.sampleDt > 0.f) || !std::isfinite(layout.sampleDt))
    throw std::invalid_argument("synthesis needs a node step sample_dt > 0");
  if (threads < 0) throw std::invalid_argument("threads must be >= 0 (0: all cores)");
  mSlots.resize(std::size_t(layout.samples));
}

int Synthesizer::liveGroups() const {
  return int(std::min<long long>(mSteps, mLayout.samples));
}

void Synthesizer::checkGroup(const PathlineGroup& g) const {
  if (!(g.layout == mLayout))
    throw std::invalid_argument(
        "pathline group (state " + std::to_string(g.state) + ", node " + std::to_string(g.step) +
        ") has " + std::to_string(g.layout.particles) + " particles x " +
        std::to_string(g.layout.samples) + " samples; the synthesis uses " +
        std::to_string(mLayout.particles) + " x " + std::to_string(mLayout.samples) +
        " with the same node step");
  const std::size_t v = mLayout.values();
  if (g.start.size() != std::size_t(mLayout.particles) || g.velocity.size() != v ||
      g.density.size() != v || g.temperature.size() != v)
    throw std::invalid_argument("pathline group arrays do not match its layout");
}

void Synthesizer::setEmitterTransform(const glm::mat4& placement) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(placement[c][r]))
        throw std::invalid_argument("emitter transform must be finite");
  if (placement[0][3] != 0.f || placement[1][3] != 0.f || placement[2][3] != 0.f || placement[3][3] != 1.f)
    throw std::invalid_argument("emitter transform must be affine (last row 0, 0, 0, 1)");
  mPlacement = placement;
}

void Synthesizer::step(const PathlineGroup& emitted, glm::vec3 externalVelocity) {
  checkGroup(emitted);
  ThreadLimit limit(mThreads);
  advance(externalVelocity, nullptr);
  emit(prepare(emitted));
}

void Synthesizer::step(const PathlineGroup& emitted, const ExternalVelocity& field) {
  checkGroup(emitted);
  ThreadLimit limit(mThreads);
  advance(glm::vec3(0.f), &field);
  emit(prepare(emitted));
}

void Synthesizer::stepNode(const PathlineFile& file, int node, int state, glm::vec3 externalVelocity) {
  std::shared_ptr<const PreparedGroup> cached = findOrRead(file, node, state);
  ThreadLimit limit(mThreads);
  advance(externalVelocity, nullptr);
  emitNode(std::move(cached));
}

void Synthesizer::stepNode(const PathlineFile& file, int node, int state, const ExternalVelocity& field) {
  std::shared_ptr<const PreparedGroup> cached = findOrRead(file, node, state);
  ThreadLimit limit(mThreads);
  advance(glm::vec3(0.f), &field);
  emitNode(std::move(cached));
}

std::shared_ptr<const PreparedGroup> Synthesizer::findOrRead(const PathlineFile& file, int node, int state) {
  std::shared_ptr<const PreparedGroup> cached = mCache->find(state, node);
  if (!cached) {
    file.readGroup(node, mRead, state);
    checkGroup(mRead);
  }
  return cached;
}

void Synthesizer::emitNode(std::shared_ptr<const PreparedGroup> cached) {
  if (!cached) {
    cached = prepare(mRead);
    mCache->insert(cached);
  }
  emit(std::move(cached));
}

void Synthesizer::recycle(std::shared_ptr<const PreparedGroup>&& g) {
  // Every prepared group is made non-const by prepare(); one no slot and no cache entry
  // references any more may be written again.
  if (g && g.use_count() == 1) mSpare = std::const_pointer_cast<PreparedGroup>(std::move(g));
  g.reset();
}

std::shared_ptr<const PreparedGroup> Synthesizer::prepare(const PathlineGroup& g) {
  // The slot emit() fills holds the group whose lifetime advance() ended: its buffers are free
  // unless the cache or a younger slot shares them. So no allocation once the ring is full.
  recycle(std::move(slotOf(mSteps - 1).group));
  std::shared_ptr<PreparedGroup> out = mSpare ? std::move(mSpare) : std::make_shared<PreparedGroup>();
  mSpare.reset();
  prepareGroup(g, *out);
  return out;
}

void Synthesizer::advance(glm::vec3 uniform, const ExternalVelocity* field) {
  const int L = mLayout.samples, P = mLayout.particles;
  const float h = mLayout.sampleDt;
  const long long first = firstLiveStep();
  // Groups at age L - 1 have no sample L to move to: their lifetime ends with this step (the
  // emission below reuses their slot). The others age by one.
  const long long end = mSteps;
  const long long moving = std::max(first, end - (L - 1));
  mExternal = field ? glm::vec3(0.f) : uniform;
  if (!field) {
    // A uniform u_ext moves every particle of a group alike: one vector per group.
    for (long long e = moving; e < end; ++e) slotOf(e).uniformOffset += h * uniform;
    ++mSteps;
    return;
  }
  const double t0 = time();
  const int chunks = (P + kChunk - 1) / kChunk;
  const int groups = int(end - moving);
  for (long long e = moving; e < end; ++e) {
    Slot& s = slotOf(e);
    if (!s.hasField) {
      s.fieldOffset.assign(std::size_t(P), glm::vec3(0.f));  // sized once per slot
      s.hasField = true;
    }
  }
  parallelFor(0, groups * chunks, [&](int task) {
    const long long e = moving + task / chunks;
    Slot& s = slotOf(e);
    const std::size_t age = std::size_t(mSteps - 1 - e);
    const int begin = (task % chunks) * kChunk, n = std::min(P, begin + kChunk) - begin;
    // Heun: e0 = u_ext(x_k, t_k), x* = x_k + Δx_path + h e0, e1 = u_ext(x*, t_k + h),
    // ∫ u_ext ≈ h (e0 + e1) / 2.
    glm::vec3 x[kChunk] = {}, u0[kChunk], u1[kChunk];
    const glm::vec3* now = s.group->path.data() + age * std::size_t(P) + std::size_t(begin);
    const glm::vec3* next = now + P;
    glm::vec3* offset = s.fieldOffset.data() + begin;
    for (int m = 0; m < n; ++m) x[m] = now[m] + s.uniformOffset + offset[m] + placementOffset(s, begin + m);
    field->evaluate(x, n, t0, u0);
    for (int m = 0; m < n; ++m) x[m] += (next[m] - now[m]) + h * u0[m];
    field->evaluate(x, n, t0 + double(h), u1);
    for (int m = 0; m < n; ++m) offset[m] += 0.5f * h * (u0[m] + u1[m]);
  });
  ++mSteps;
}

void Synthesizer::emit(std::shared_ptr<const PreparedGroup> g) {
  Slot& s = slotOf(mSteps - 1);
  recycle(std::move(s.group));
  s.group = std::move(g);
  s.emittedAt = mSteps - 1;
  s.uniformOffset = glm::vec3(0.f);
  s.placement = mPlacement;
  s.placed = mPlacement != glm::mat4(1.f);
  if (s.hasField) std::fill(s.fieldOffset.begin(), s.fieldOffset.end(), glm::vec3(0.f));
}

void Synthesizer::gather(SynthParticles& out) const {
  ThreadLimit limit(mThreads);
  const int P = mLayout.particles;
  const int groups = liveGroups();
  const std::size_t count = particleCount();
  out.positions.resize(count);
  out.density.resize(count);
  out.temperature.resize(count);
  out.velocity.resize(count);
  const long long first = firstLiveStep();
  const int chunks = (P + kChunk - 1) / kChunk;
  parallelFor(0, groups * chunks, [&](int task) {
    const int gi = task / chunks;
    const Slot& s = slotOf(first + gi);
    const PreparedGroup& g = *s.group;
    const std::size_t age = std::size_t(mSteps - 1 - (first + gi));
    const int begin = (task % chunks) * kChunk, end = std::min(P, begin + kChunk);
    const std::size_t in = age * std::size_t(P), at = std::size_t(gi) * std::size_t(P);
    for (int p = begin; p < end; ++p) {
      glm::vec3 x = g.path[in + std::size_t(p)] + s.uniformOffset;
      if (s.hasField) x += s.fieldOffset[std::size_t(p)];
      x += placementOffset(s, p);
      out.positions[at + std::size_t(p)] = x;
      out.density[at + std::size_t(p)] = g.density[in + std::size_t(p)];
      out.temperature[at + std::size_t(p)] = g.temperature[in + std::size_t(p)];
      out.velocity[at + std::size_t(p)] = g.velocity[in + std::size_t(p)] + mExternal;
    }
  });
}

}  // namespace plume
