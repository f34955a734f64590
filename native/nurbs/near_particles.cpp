#include "nurbs/near_particles.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace plume {
namespace {

/// Bucket coordinates are kept within ±2^20, so three of them pack into 63 bits.
constexpr int kBias = 1 << 20;

}  // namespace

NearParticles::NearParticles(const std::vector<glm::vec3>& particles, double bucketSize)
    : mSize(bucketSize) {
  if (!std::isfinite(bucketSize) || !(bucketSize > 0.0))
    throw std::invalid_argument("bucket size must be finite and > 0");
  for (const glm::vec3& p : particles)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw std::invalid_argument("particle positions must be finite");
  if (particles.empty()) return;
  std::vector<std::uint64_t> keys(particles.size());
  mLo = mHi = bucketOf(particles.front());
  for (std::size_t n = 0; n < particles.size(); ++n) {
    const glm::ivec3 b = bucketOf(particles[n]);
    mLo = glm::min(mLo, b);
    mHi = glm::max(mHi, b);
    keys[n] = key(b);
  }
  std::vector<std::size_t> order(particles.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return keys[a] < keys[b]; });
  mPoints.reserve(order.size());
  mKeys.reserve(order.size());
  for (std::size_t n : order) {
    mPoints.push_back(particles[n]);
    mKeys.push_back(keys[n]);
  }
}

glm::ivec3 NearParticles::bucketOf(glm::vec3 p) const {
  glm::ivec3 b;
  for (int a = 0; a < 3; ++a)
    b[a] = int(std::clamp(std::floor(double(p[a]) / mSize), double(-kBias + 1), double(kBias - 1)));
  return b;
}

std::uint64_t NearParticles::key(glm::ivec3 b) {
  return (std::uint64_t(b.x + kBias) << 42) | (std::uint64_t(b.y + kBias) << 21) |
         std::uint64_t(b.z + kBias);
}

double NearParticles::nearest(glm::vec3 q) const {
  double best = std::numeric_limits<double>::infinity();
  if (mPoints.empty()) return best;
  const glm::ivec3 c = bucketOf(q);
  // Shells r = 0, 1, 2, ...: buckets at Chebyshev distance r from q's, clipped to the buckets
  // that hold particles (so a query far outside them costs no more than one inside). A particle
  // in shell r or farther is at least (r - 1) bucket sizes away: stop once best is below that.
  const glm::ivec3 below = glm::max(mLo - c, glm::ivec3(0)), above = glm::max(c - mHi, glm::ivec3(0));
  const int first = std::max({below.x, below.y, below.z, above.x, above.y, above.z});
  const glm::ivec3 far = glm::max(glm::abs(c - mLo), glm::abs(c - mHi));
  const int last = std::max({far.x, far.y, far.z});
  for (int r = first; r <= last; ++r) {
    if (r > 0 && best <= double(r - 1) * mSize) break;
    const glm::ivec3 lo = glm::max(c - r, mLo), hi = glm::min(c + r, mHi);
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
          const glm::ivec3 b(x, y, z);
          const glm::ivec3 d = glm::abs(b - c);
          if (std::max({d.x, d.y, d.z}) != r) continue;  // inside the shell, seen already
          const auto range = std::equal_range(mKeys.begin(), mKeys.end(), key(b));
          for (auto it = range.first; it != range.second; ++it) {
            const glm::vec3& p = mPoints[std::size_t(it - mKeys.begin())];
            best = std::min(best, glm::length(glm::dvec3(p) - glm::dvec3(q)));
          }
        }
  }
  return best;
}

}  // namespace plume
