/// \file flow_noise.cpp
/// Gradient noise with rotating gradients (Perlin & Neyret 2001), three components per lookup.

#include "flames/flow_noise.h"

#include "core/format.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

/// Perlin's 12 cube-edge gradients plus 4 repeats (improved noise, 2002): 16 for a 4-bit index.
constexpr float kGradients[16][3] = {{1, 1, 0},  {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1},  {-1, 0, 1},
                                      {1, 0, -1}, {-1, 0, -1}, {0, 1, 1},  {0, -1, 1}, {0, 1, -1}, {0, -1, -1},
                                      {1, 1, 0},  {-1, 1, 0}, {0, -1, 1}, {0, -1, -1}};

/// SplitMix64's finalizer: the lattice hash of seed ^ i·C₁ ^ j·C₂ ^ k·C₃.
std::uint64_t mixLattice(std::uint64_t h) {
  h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
  h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
  return h ^ (h >> 31);
}

constexpr double kTwoPi = 6.283185307179586;

float fade(float t) { return t * t * t * (t * (t * 6.f - 15.f) + 10.f); }

}  // namespace

void FlowNoiseParams::validate() const {
  auto bound = [](double v) { return formatNumber(v); };
  if (!(amplitude >= 0.0 && amplitude <= kMaxFlowNoiseAmplitude))
    throw std::invalid_argument("flow_noise_amplitude must be in [0, " + bound(kMaxFlowNoiseAmplitude) +
                                "] widest radii (got " + bound(amplitude) + ")");
  if (!(scale > 0.0 && scale <= kMaxFlowNoiseScale))
    throw std::invalid_argument("flow_noise_scale (lambda) must be in (0, " + bound(kMaxFlowNoiseScale) +
                                "] widest radii (got " + bound(scale) + ")");
  if (!(frequency >= 0.0 && frequency <= kMaxFlowNoiseFrequency))
    throw std::invalid_argument("flow_noise_frequency (nu) must be in [0, " + bound(kMaxFlowNoiseFrequency) +
                                "] Hz (got " + bound(frequency) + ")");
  if (!(rotation >= 0.0 && rotation <= kMaxFlowNoiseRotation))
    throw std::invalid_argument("flow_noise_rotation must be in [0, " + bound(kMaxFlowNoiseRotation) +
                                "] rad·m/s (got " + bound(rotation) + ")");
}

FlowNoise::FlowNoise(const FlowNoiseParams& params, std::uint64_t seed) : mParams(params), mSeed(seed) {
  params.validate();
}

double FlowNoise::rotationRate(double sourceRadius) const {
  return mParams.rotation / (2.0 * std::max(sourceRadius, 1e-6));
}

glm::dvec3 FlowNoise::noise(const glm::dvec3& q, double phi) const {
  // Lattice cell in double (exact integers), everything inside it in single precision: the
  // noise is a smooth O(1) function of the cell offsets, so it changes by float rounding only.
  const double fx = std::floor(q.x), fy = std::floor(q.y), fz = std::floor(q.z);
  const auto ix = std::int64_t(fx), iy = std::int64_t(fy), iz = std::int64_t(fz);
  const glm::vec3 f(float(q.x - fx), float(q.y - fy), float(q.z - fz));
  const glm::vec3 w(fade(f.x), fade(f.y), fade(f.z));
  // The rotation after reducing φ to [−π, π] in double (the gradients turn by φ to ~3e-7 rad
  // at any time).
  const float reduced = float(phi - kTwoPi * std::nearbyint(phi * (1.0 / kTwoPi)));
  const float c = std::cos(reduced), s = std::sin(reduced);
  // The lattice hash's per-axis terms, once per axis and side (hashLattice() spelled out).
  const std::uint64_t hx[2] = {std::uint64_t(ix) * 0x9E3779B97F4A7C15ull, std::uint64_t(ix + 1) * 0x9E3779B97F4A7C15ull};
  const std::uint64_t hy[2] = {std::uint64_t(iy) * 0xC2B2AE3D27D4EB4Full, std::uint64_t(iy + 1) * 0xC2B2AE3D27D4EB4Full};
  const std::uint64_t hz[2] = {std::uint64_t(iz) * 0x165667B19E3779F9ull, std::uint64_t(iz + 1) * 0x165667B19E3779F9ull};
  // Per axis and side, the offsets d and the weights (the same float values the corners form).
  const float dx[2] = {f.x - 0.f, f.x - 1.f}, dy[2] = {f.y - 0.f, f.y - 1.f}, dz[2] = {f.z - 0.f, f.z - 1.f};
  const float wx[2] = {1.f - w.x, w.x}, wy[2] = {1.f - w.y, w.y}, wz[2] = {1.f - w.z, w.z};
  const std::uint64_t sx[2] = {mSeed ^ hx[0], mSeed ^ hx[1]};
  glm::vec3 sum(0.f);
  auto corner = [&](int a, int b, int e) {
    const std::uint64_t h = mixLattice(sx[a] ^ hy[b] ^ hz[e]);
    // Rotation about the profile axis by ±φ (bit 12 picks the sense): (gx, gy) · (dx, dy) with
    // g turned by ±φ is g · (d turned by ∓φ), so d turns once for the three components.
    // s · (1 − 2·bit) is ±s exactly.
    const float sn = (h >> 12) & 1 ? -s : s;
    const float rx = c * dx[a] + sn * dy[b], ry = c * dy[b] - sn * dx[a];
    const float* g0 = kGradients[h & 15];
    const float* g1 = kGradients[(h >> 4) & 15];
    const float* g2 = kGradients[(h >> 8) & 15];
    const glm::vec3 value(g0[0] * rx + g0[1] * ry + g0[2] * dz[e], g1[0] * rx + g1[1] * ry + g1[2] * dz[e],
                          g2[0] * rx + g2[1] * ry + g2[2] * dz[e]);
    const float weight = wx[a] * wy[b] * wz[e];
    sum += weight * value;
  };
  // Corners in the order corner = a + 2b + 4e (the sum's order).
  corner(0, 0, 0), corner(1, 0, 0), corner(0, 1, 0), corner(1, 1, 0);
  corner(0, 0, 1), corner(1, 0, 1), corner(0, 1, 1), corner(1, 1, 1);
  return glm::dvec3(sum);
}

glm::dvec3 FlowNoise::displacement(const glm::dvec3& p, double tau, double sourceRadius) const {
  if (mParams.amplitude <= 0.0) return glm::dvec3(0.0);
  const glm::dvec3 q(p.x / mParams.scale, p.y / mParams.scale, mParams.frequency * tau);
  return mParams.amplitude * noise(q, rotationRate(sourceRadius) * tau);
}

}  // namespace plume
