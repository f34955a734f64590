#include "solver/source_noise.h"

#include <cmath>
#include <initializer_list>

namespace plume {
namespace {

/// A lattice value in [0, 1) from four integer coordinates, the seed and the stream
/// (SplitMix64 finalizer over a combined key).
float latticeValue(std::int64_t x, std::int64_t y, std::int64_t z, std::int64_t w,
                   std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t h = seed * 0x9E3779B97F4A7C15ull ^ stream * 0xC2B2AE3D27D4EB4Full;
  for (std::int64_t v : {x, y, z, w}) {
    h ^= std::uint64_t(v) + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
    h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
    h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
    h ^= h >> 31;
  }
  return float(h >> 40) * (1.f / 16777216.f);
}

float fade(float t) { return t * t * t * (t * (t * 6.f - 15.f) + 10.f); }

/// One octave: the 16 lattice values around (q, s) blended by quintic fades.
float valueNoise4(const glm::vec3& q, double s, std::uint64_t seed, std::uint64_t stream) {
  const glm::vec3 f = glm::floor(q);
  const double fs = std::floor(s);
  const glm::vec3 u(fade(q.x - f.x), fade(q.y - f.y), fade(q.z - f.z));
  const float uw = fade(float(s - fs));
  const std::int64_t x0 = std::int64_t(f.x), y0 = std::int64_t(f.y), z0 = std::int64_t(f.z);
  const std::int64_t w0 = std::int64_t(fs);
  float acc[2];
  for (int dw = 0; dw < 2; ++dw) {
    float zs[2];
    for (int dz = 0; dz < 2; ++dz) {
      float ys[2];
      for (int dy = 0; dy < 2; ++dy) {
        const float a = latticeValue(x0, y0 + dy, z0 + dz, w0 + dw, seed, stream);
        const float b = latticeValue(x0 + 1, y0 + dy, z0 + dz, w0 + dw, seed, stream);
        ys[dy] = a + u.x * (b - a);
      }
      zs[dz] = ys[0] + u.y * (ys[1] - ys[0]);
    }
    acc[dw] = zs[0] + u.z * (zs[1] - zs[0]);
  }
  return acc[0] + uw * (acc[1] - acc[0]);
}

}  // namespace

float sourceNoiseValue(const glm::vec3& p, double t, const SourceNoise& noise, std::uint64_t seed,
                       std::uint64_t stream) {
  const float inv = noise.scale > 0.f ? 1.f / noise.scale : 0.f;
  const double s = t * double(noise.rate);
  // Two octaves, the second twice as fine and twice as fast at half the weight; the sum spread
  // back over [0, 1] (its values gather around the middle, so stretch them by 1.5 and clamp).
  const float v = (2.f * valueNoise4(p * inv, s, seed, stream) +
                   valueNoise4(p * (2.f * inv) + glm::vec3(17.3f), 2.0 * s + 5.1, seed,
                               stream + 0x5A5Aull)) / 3.f;
  const float spread = 0.5f + 1.5f * (v - 0.5f);
  return spread < 0.f ? 0.f : (spread > 1.f ? 1.f : spread);
}

}  // namespace plume
