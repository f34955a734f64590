#include "nurbs/near_particles.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace plume {
namespace {

/// At most this many buckets over the particles' box (16 MB of offsets): a larger box doubles
/// the bucket size, which keeps nearest() exact and only makes it search more particles.
constexpr double kMaxBuckets = 4.0 * 1024.0 * 1024.0;
/// Bucket coordinates are clamped to ±2^20 (particles farther out share the edge buckets).
constexpr double kBias = double(1 << 20);

}  // namespace

NearParticles::NearParticles(const std::vector<glm::vec3>& particles, double bucketSize)
    : mSize(bucketSize) {
  if (!std::isfinite(bucketSize) || !(bucketSize > 0.0))
    throw std::invalid_argument("bucket size must be finite and > 0");
  for (const glm::vec3& p : particles)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw std::invalid_argument("particle positions must be finite");
  if (particles.empty()) return;
  if (particles.size() >= std::size_t(std::numeric_limits<std::uint32_t>::max()))
    throw std::invalid_argument("too many particles for a nearest-particle search");
  glm::dvec3 lo(particles.front()), hi(particles.front());
  for (const glm::vec3& p : particles) {
    lo = glm::min(lo, glm::dvec3(p));
    hi = glm::max(hi, glm::dvec3(p));
  }
  for (;;) {  // the bucket range, with the size doubled until the offsets fit
    mLo = bucketOf(glm::vec3(lo));
    mHi = bucketOf(glm::vec3(hi));
    mDims = mHi - mLo + 1;
    if (double(mDims.x) * double(mDims.y) * double(mDims.z) <= kMaxBuckets) break;
    mSize *= 2.0;
  }
  // Counting sort of the particles by bucket: mStart[b] .. mStart[b + 1] are bucket b's.
  mStart.assign(std::size_t(mDims.x) * std::size_t(mDims.y) * std::size_t(mDims.z) + 1, 0);
  std::vector<std::uint32_t> slot(particles.size());
  for (std::size_t n = 0; n < particles.size(); ++n) {
    slot[n] = std::uint32_t(linear(bucketOf(particles[n])));
    ++mStart[slot[n] + 1];
  }
  for (std::size_t b = 1; b < mStart.size(); ++b) mStart[b] += mStart[b - 1];
  std::vector<std::uint32_t> fill(mStart.begin(), mStart.end() - 1);
  mPoints.resize(particles.size());
  for (std::size_t n = 0; n < particles.size(); ++n) mPoints[fill[slot[n]]++] = particles[n];
}

glm::ivec3 NearParticles::bucketOf(glm::vec3 p) const {
  glm::ivec3 b;
  for (int a = 0; a < 3; ++a)
    b[a] = int(std::clamp(std::floor(double(p[a]) / mSize), -kBias + 1.0, kBias - 1.0));
  return b;
}

std::size_t NearParticles::linear(glm::ivec3 b) const {
  const glm::ivec3 r = b - mLo;
  return (std::size_t(r.z) * std::size_t(mDims.y) + std::size_t(r.y)) * std::size_t(mDims.x) +
         std::size_t(r.x);
}

double NearParticles::nearest(glm::vec3 q) const {
  double best = std::numeric_limits<double>::infinity();
  if (mPoints.empty()) return best;
  const glm::ivec3 c = bucketOf(q);
  // Shells r = 0, 1, 2, ...: buckets at Chebyshev distance r from q's, clipped to the buckets
  // that hold particles (so a query far outside them costs no more than one inside). Shell r lies
  // outside the cube of buckets c ± (r − 1), whose nearest face is (r − 1) bucket sizes plus q's
  // least distance to its own bucket's faces away: stop once best is below that.
  double inside = mSize;
  for (int a = 0; a < 3; ++a) {
    const double f = double(q[a]) - double(c[a]) * mSize;
    inside = std::min({inside, std::max(f, 0.0), std::max(mSize - f, 0.0)});
  }
  const glm::ivec3 below = glm::max(mLo - c, glm::ivec3(0)), above = glm::max(c - mHi, glm::ivec3(0));
  const int first = std::max({below.x, below.y, below.z, above.x, above.y, above.z});
  const glm::ivec3 far = glm::max(glm::abs(c - mLo), glm::abs(c - mHi));
  const int last = std::max({far.x, far.y, far.z});
  const glm::dvec3 qd(q);
  for (int r = first; r <= last; ++r) {
    if (r > 0 && best <= double(r - 1) * mSize + inside) break;
    const glm::ivec3 lo = glm::max(c - r, mLo), hi = glm::min(c + r, mHi);
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y) {
        // Inside the shell only the two x ends are new, unless y or z is on the shell.
        const bool whole = std::abs(z - c.z) == r || std::abs(y - c.y) == r;
        for (int x = lo.x; x <= hi.x; x += (whole || hi.x == lo.x) ? 1 : hi.x - lo.x) {
          if (!whole && std::abs(x - c.x) != r) continue;
          const std::size_t b = linear(glm::ivec3(x, y, z));
          for (std::uint32_t i = mStart[b]; i < mStart[b + 1]; ++i)
            best = std::min(best, glm::length(glm::dvec3(mPoints[i]) - qd));
        }
      }
  }
  return best;
}

}  // namespace plume
