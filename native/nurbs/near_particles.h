#pragma once
/// \file near_particles.h
/// How far control points are from the smoke ([Smoke Surfaces] §3.3 with an editable net:
/// a control point an artist grabs should sit among the particles it shapes): distances from
/// query points to the nearest of a set of particles, through a uniform bucket grid.

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace plume {

/// The particles sorted into cubic buckets of side `bucketSize` (world units; doubled until the
/// particles' box has at most 4 M buckets), with a dense table of each bucket's particles.
class NearParticles {
 public:
  /// Throws std::invalid_argument unless bucketSize is finite and > 0 and the points finite.
  NearParticles(const std::vector<glm::vec3>& particles, double bucketSize);

  bool empty() const { return mPoints.empty(); }
  /// Distance from q to the nearest particle (exact: buckets are searched in growing shells
  /// until no farther shell can hold a nearer one); +inf when there are no particles.
  double nearest(glm::vec3 q) const;

 private:
  glm::ivec3 bucketOf(glm::vec3 p) const;
  std::size_t linear(glm::ivec3 b) const;  ///< index of bucket b in mStart (b within mLo..mHi)

  double mSize;
  std::vector<glm::vec3> mPoints;       ///< sorted by bucket
  std::vector<std::uint32_t> mStart;    ///< bucket b's points: mStart[b] .. mStart[b + 1]
  glm::ivec3 mLo{0}, mHi{0}, mDims{0};  ///< bucket range holding points, and its size
};

}  // namespace plume
