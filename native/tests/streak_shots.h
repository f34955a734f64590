#pragma once
/// \file streak_shots.h
/// Streak frames for the tests of §3.3 ([Smoke Surfaces]): random clouds, clustered plumes,
/// coincident streaklines and straight parallel lines, each from a seed.

#include "core/rng.h"
#include "streak/streak_group.h"
#include "tracers/streak_frame.h"

#include <glm/glm.hpp>

#include <memory>
#include <numeric>
#include <vector>

namespace plume {

/// Random frames: `sources` streaklines, N(t) = n[t] particles each (N may be 0 or shrink).
inline std::vector<StreakFrame> randomFrames(int sources, const std::vector<int>& n,
                                             std::uint64_t seed) {
  Rng rng(seed);
  std::vector<StreakFrame> frames;
  for (int count : n) {
    StreakFrame f;
    f.counts.assign(std::size_t(sources), count);
    f.groups.assign(std::size_t(sources), 0);
    for (int s = 0; s < sources; ++s)
      for (int i = 0; i < count; ++i) {
        // Sources drift apart by s so that h varies over a wide range.
        f.positions.push_back(glm::vec3(float(rng.uniform(-1, 1)) + 0.1f * float(s),
                                        float(rng.uniform(-1, 1)), float(rng.uniform(0, 2))));
        f.density.push_back(float(rng.uniform()));
        f.outside.push_back(rng.uniform() < 0.1 ? 1 : 0);
      }
    frames.push_back(std::move(f));
  }
  return frames;
}

/// How the sources of plumeFrames() lie.
enum class Layout {
  Clustered,   ///< blobs of sources whose streaklines move together (surfaces to find)
  Uniform,     ///< every particle independent and uniform in a box
  Coincident,  ///< clustered, and every third source a copy of another (h = 0: ties everywhere)
};

/// A plume-like shot: `blobs` groups of sources, interleaved (source s in blob s % blobs) so
/// that clusters are not runs of IDs; particle i of a source on frame t follows its blob's
/// coherent wander plus a small wander of its own, rising with age. N(t) = n[t].
inline std::vector<StreakFrame> plumeFrames(int sources, const std::vector<int>& n, Layout layout,
                                            int blobs, std::uint64_t seed) {
  Rng rng(seed, /*stream=*/1);
  std::vector<glm::vec3> start(static_cast<std::size_t>(sources));
  std::vector<glm::vec3> blobCentre(static_cast<std::size_t>(blobs));
  for (glm::vec3& c : blobCentre)
    c = glm::vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(0, 0.3));
  for (int s = 0; s < sources; ++s)
    start[std::size_t(s)] = blobCentre[std::size_t(s % blobs)] +
                            0.03f * glm::vec3(rng.normal(), rng.normal(), rng.normal());
  std::vector<StreakFrame> frames;
  for (std::size_t t = 0; t < n.size(); ++t) {
    StreakFrame f;
    const int count = n[t];
    f.counts.assign(std::size_t(sources), count);
    f.groups.assign(std::size_t(sources), 0);
    for (int s = 0; s < sources; ++s)
      for (int i = 0; i < count; ++i) {
        const float age = float(count - i);
        glm::vec3 p;
        if (layout == Layout::Uniform) {
          p = glm::vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(0, 2));
        } else {
          // The blob's wander depends on (blob, t, i) only: every source of the blob shares it.
          Rng shared(seed, 1000003ull * std::uint64_t(s % blobs) + 1009ull * t + std::uint64_t(i));
          const glm::vec3 wander(shared.normal(), shared.normal(), shared.normal());
          p = start[std::size_t(s)] + glm::vec3(0.f, 0.f, 0.05f * age) + 0.02f * age * wander +
              0.01f * glm::vec3(rng.normal(), rng.normal(), rng.normal());
        }
        f.positions.push_back(p);
        f.density.push_back(1.f);
        f.outside.push_back(0);
      }
    if (layout == Layout::Coincident) {
      const std::vector<std::size_t> o = f.offsets();
      for (int s = 2; s < sources; s += 3)  // a copy of the source before it
        for (int i = 0; i < count; ++i)
          f.positions[o[std::size_t(s)] + std::size_t(i)] =
              f.positions[o[std::size_t(s) - 1] + std::size_t(i)];
    }
    frames.push_back(std::move(f));
  }
  return frames;
}

/// Frames of parallel straight streaklines: source s at slot slotOfSource[s] · d along x,
/// particles rising along z and fanning out with height.
inline std::vector<StreakFrame> parallelStreaks(const std::vector<int>& slotOfSource, float d,
                                                int frames) {
  std::vector<StreakFrame> out;
  const int n = int(slotOfSource.size());
  for (int t = 0; t < frames; ++t) {
    StreakFrame f;
    const int N = t + 1;
    f.counts.assign(std::size_t(n), N);
    f.groups.assign(std::size_t(n), 0);
    for (int s = 0; s < n; ++s)
      for (int i = 0; i < N; ++i) {
        const float slot = float(slotOfSource[std::size_t(s)]);
        const float height = float(N - i);
        f.positions.push_back(glm::vec3(slot * d * (1.f + 0.01f * height), 0.f, 0.1f * height));
        f.density.push_back(1.f);
        f.outside.push_back(0);
      }
    out.push_back(std::move(f));
  }
  return out;
}

/// The frames as the shared pointer StreakGroup takes (a copy the group owns).
inline SharedStreakFrames share(std::vector<StreakFrame> frames) {
  return std::make_shared<const std::vector<StreakFrame>>(std::move(frames));
}

/// 0, 1, ..., n-1.
inline std::vector<int> iota(int n) {
  std::vector<int> v(static_cast<std::size_t>(n));
  std::iota(v.begin(), v.end(), 0);
  return v;
}

}  // namespace plume
