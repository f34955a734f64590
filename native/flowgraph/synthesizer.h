#pragma once
/// \file synthesizer.h
/// Fire synthesis from a walk on the flow graph ([Graph Fire Synthesis] §5.2, eq. 13,
/// Algorithm 1): each visited node emits its group's particles at their start positions; every
/// particle then follows its own pathline's velocity samples plus an external velocity,
///   x_{k+1} = x_k + ∫_{t_k}^{t_k + Δt_n} [u(t) + u_ext(t)] dt,              (13)
/// carries its pathline's density and temperature, and is removed after its lifetime of L
/// samples. A transition (a visited node that is not the successor of the previous one) only
/// changes which group is emitted: particles already alive keep their own pathline.
///
/// Quadrature. u(t) is known at the samples, Δt_n apart: the pathline part of eq. 13 is the
/// trapezoid rule between the samples of the particle's age a and a + 1,
///   ∫ u dt ≈ Δt_n (u_a + u_{a+1}) / 2,
/// second order: over a lifetime it differs from the recorded pathline by at most
/// t_max Δt_n² max|ü| / 12 (ü: second time derivative of the velocity along the pathline). A
/// uniform u_ext is given per step (constant over it); a field u_ext(x, t) is integrated with
/// Heun's method (trapezoid with an Euler predictor), also second order.
///
/// Layout and cost. The pathline part of a particle's position does not depend on u_ext, so it
/// is summed once per group (prepared_group.h: sample-major positions, density and temperature)
/// and the ring of L slots only references that immutable prepared group; what u_ext adds is
/// kept per slot: one vector for a uniform u_ext, one per particle once a field is used. A step
/// with a uniform u_ext therefore costs O(L) plus, for a node not in the cache of prepared
/// groups (prepared_group_cache.h), its read and preparation (|Ω| L values); a cached node is
/// emitted in O(1), and a node visited twice within L steps is shared by both slots. Positions
/// are formed (pathline part + external part) by gather(). Parallel over particles with fixed
/// chunks, so results do not depend on the thread count, nor on the cache.

#include "fields/velocity_field.h"
#include "flowgraph/pathline_group.h"
#include "flowgraph/prepared_group.h"
#include "flowgraph/prepared_group_cache.h"

#include <glm/glm.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace plume {

class PathlineFile;

/// Live particles as gathered: world positions, density and temperature from the samples of
/// their age (oldest group first, particle order within a group).
struct SynthParticles {
  std::vector<glm::vec3> positions;
  std::vector<float> density;
  std::vector<float> temperature;
  /// u of their pathline at their age plus the last step's uniform u_ext (m/s): motion blur.
  std::vector<glm::vec3> velocity;
  std::size_t size() const { return positions.size(); }
};

/// Particles of a synthesized fire (see the file comment).
class Synthesizer {
 public:
  /// Every emitted group must have `layout` (|Ω| >= 1, L >= 2, Δt_n > 0: std::invalid_argument
  /// otherwise). `threads`: worker threads (0: all cores). `cacheBytes`: budget of the cache of
  /// prepared groups stepNode() keeps between visits (0: every visit reads its file).
  explicit Synthesizer(const PathlineLayout& layout, int threads = 0, std::size_t cacheBytes = 0);
  /// The same with a cache shared with other synthesizers of the same graph (the add-on keeps one
  /// per graph across syntheses, so synthesizing again with another seed or other keys reads no
  /// group twice). Its keys (state, node) must mean the same files for all of them. Not null.
  Synthesizer(const PathlineLayout& layout, int threads, std::shared_ptr<PreparedGroupCache> cache);

  const PathlineLayout& layout() const { return mLayout; }

  /// One synthesis step (Algorithm 1): particles alive move over Δt_n by eq. 13 with the uniform
  /// external velocity `externalVelocity` (m/s, constant over the step) and age by one; those
  /// at the end of their lifetime are removed; then `emitted` (the visited node) emits its
  /// particles at their start positions. Throws std::invalid_argument when `emitted` does not
  /// have the layout or its arrays do not match it.
  void step(const PathlineGroup& emitted, glm::vec3 externalVelocity = glm::vec3(0.f));
  /// The same with u_ext(x, t) from a field (Heun's method per particle).
  void step(const PathlineGroup& emitted, const ExternalVelocity& field);

  /// step() emitting node `node` of `file`, the pathline file of state `state`: taken from the
  /// cache of prepared groups (a hit: O(1)) or read, prepared and cached (a miss). The same
  /// particles as step(file.readGroup(node, state), ...). (state, node) is the cache key: use
  /// one file per state for the synthesizer's life. Throws as readGroup() and step() do, before
  /// anything changes.
  void stepNode(const PathlineFile& file, int node, int state, glm::vec3 externalVelocity = glm::vec3(0.f));
  void stepNode(const PathlineFile& file, int node, int state, const ExternalVelocity& field);
  /// The placement of the groups emitted from now on (§5.2's fire attached to a moving object,
  /// the paper's fire blade): an affine map E applied to the start positions x_0 of a group at
  /// its emission; the particles then keep their pathline's world-space motion,
  ///   x(a) = E x_0 + (path(a) − x_0) + ∫ u_ext,
  /// so a moving source trails fire (each group stays where it was emitted) and a tilted one
  /// still burns upwards. Identity by default (groups emitted where they were recorded). Throws
  /// std::invalid_argument unless finite with a last row (0, 0, 0, 1).
  void setEmitterTransform(const glm::mat4& placement);
  const glm::mat4& emitterTransform() const { return mPlacement; }

  /// The cache stepNode() uses: its hits, misses (file reads) and bytes.
  const PreparedGroupCache& cache() const { return *mCache; }

  /// Steps taken. After step n (counting from 0) the particles are at synthesis time n Δt_n.
  long long steps() const { return mSteps; }
  double time() const { return mSteps > 0 ? double(mSteps - 1) * double(mLayout.sampleDt) : 0.0; }
  /// Groups alive (at most L) and their particles.
  int liveGroups() const;
  std::size_t particleCount() const { return std::size_t(liveGroups()) * std::size_t(mLayout.particles); }
  /// Step at which the oldest live group was emitted (groups emitted at firstLiveStep(),
  /// firstLiveStep() + 1, ..., steps() - 1 are alive, oldest first in gather()).
  long long firstLiveStep() const { return mSteps - liveGroups(); }

  /// Positions, density and temperature of every live particle into `out` (buffers reused).
  void gather(SynthParticles& out) const;

 private:
  struct Slot {
    long long emittedAt = -1;
    std::shared_ptr<const PreparedGroup> group;  ///< eq. 13 without u_ext, shared, immutable
    glm::vec3 uniformOffset{0.f};          ///< ∫ of the uniform u_ext since emission
    std::vector<glm::vec3> fieldOffset;    ///< ∫ of field u_ext since emission, per particle
    bool hasField = false;
    glm::mat4 placement{1.f};  ///< E at emission (setEmitterTransform())
    bool placed = false;       ///< E is not the identity
  };
  /// E x_0 − x_0 of particle p of slot s: what the placement adds to its pathline position.
  static glm::vec3 placementOffset(const Slot& s, int p) {
    if (!s.placed) return glm::vec3(0.f);
    const glm::vec3 x0 = s.group->path[std::size_t(p)];
    return glm::vec3(s.placement * glm::vec4(x0, 1.f)) - x0;
  }
  void advance(glm::vec3 uniform, const ExternalVelocity* field);
  /// The group to emit at step `node` of `file`: cached, or read into mRead (nullptr: a miss).
  std::shared_ptr<const PreparedGroup> findOrRead(const PathlineFile& file, int node, int state);
  /// After advance(): prepares `g` into a buffer no longer referenced (or a new one).
  std::shared_ptr<const PreparedGroup> prepare(const PathlineGroup& g);
  /// After advance(): mRead prepared and cached when `cached` is null; emitted.
  void emitNode(std::shared_ptr<const PreparedGroup> cached);
  void emit(std::shared_ptr<const PreparedGroup> g);
  /// Keeps `g` as the spare buffer of prepare() when nothing else references it.
  void recycle(std::shared_ptr<const PreparedGroup>&& g);
  void checkGroup(const PathlineGroup& g) const;
  Slot& slotOf(long long emittedAt) { return mSlots[std::size_t(emittedAt % mLayout.samples)]; }
  const Slot& slotOf(long long emittedAt) const {
    return mSlots[std::size_t(emittedAt % mLayout.samples)];
  }

  PathlineLayout mLayout;
  int mThreads;
  std::vector<Slot> mSlots;  ///< ring of L: the group emitted at step n lives in slot n mod L
  long long mSteps = 0;
  glm::vec3 mExternal{0.f};  ///< the last step's uniform u_ext (a field's is not added)
  glm::mat4 mPlacement{1.f};  ///< E for the next emissions
  std::shared_ptr<PreparedGroupCache> mCache;
  PathlineGroup mRead;                   ///< buffers of stepNode()'s file reads
  std::shared_ptr<PreparedGroup> mSpare;  ///< a prepared group no slot or cache references
};

}  // namespace plume
