#pragma once
/// \file near_particles.h
/// How far control points are from the smoke (smoke_surfaces.txt §3.3 with an editable net:
/// a control point an artist grabs should sit among the particles it shapes): distances from
/// query points to the nearest of a set of particles, through a uniform bucket grid.

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace plume {

/// The particles sorted into cubic buckets of side `bucketSize` (world units).
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
  static std::uint64_t key(glm::ivec3 b);

  double mSize;
  std::vector<glm::vec3> mPoints;       ///< sorted by bucket key
  std::vector<std::uint64_t> mKeys;     ///< bucket key of each point, ascending
  glm::ivec3 mLo{0}, mHi{0};            ///< bucket range holding points
};

}  // namespace plume
