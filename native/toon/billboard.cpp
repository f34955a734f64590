/// \file billboard.cpp
/// Stencil rotation and stretch from the projected velocity ([Cartoon Smoke] Figure 4).

#include "toon/billboard.h"

#include "core/parallel.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

constexpr int kChunk = 1024;

/// Orthonormal camera frame (scale in the matrix is ignored: speeds stay in world m/s).
struct CameraFrame {
  glm::dvec3 right, up, back, location;
  glm::dvec3 toCamera(glm::dvec3 v) const { return {glm::dot(v, right), glm::dot(v, up), glm::dot(v, back)}; }
};

CameraFrame cameraFrame(const glm::dmat4& m) {
  return {glm::normalize(glm::dvec3(m[0])), glm::normalize(glm::dvec3(m[1])),
          glm::normalize(glm::dvec3(m[2])), glm::dvec3(m[3])};
}

}  // namespace

void ToonCamera::validate() const {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(matrixWorld[c][r]))
        throw std::invalid_argument("camera_matrix must be finite");
  if (matrixWorld[0][3] != 0.0 || matrixWorld[1][3] != 0.0 || matrixWorld[2][3] != 0.0 ||
      matrixWorld[3][3] != 1.0)
    throw std::invalid_argument("camera_matrix must be affine (last row 0, 0, 0, 1)");
  for (int c = 0; c < 3; ++c)
    if (!(glm::length(glm::dvec3(matrixWorld[c])) > 0.0))
      throw std::invalid_argument("camera_matrix must have non-zero axes (a zero-scaled camera?)");
}

Billboards computeBillboards(const ToonCamera& camera, const std::vector<glm::vec3>& positions,
                             const std::vector<glm::vec3>& velocities, float stretchFactor) {
  camera.validate();
  if (!(stretchFactor >= 0.f) || !std::isfinite(stretchFactor))
    throw std::invalid_argument("stretch_factor must be a finite number >= 0 s/m (got " +
                                std::to_string(stretchFactor) + ")");
  if (positions.size() != velocities.size())
    throw std::invalid_argument("billboards: " + std::to_string(velocities.size()) +
                                " velocities for " + std::to_string(positions.size()) +
                                " positions");
  const CameraFrame f = cameraFrame(camera.matrixWorld);
  const std::size_t n = positions.size();
  Billboards out;
  out.angle.resize(n);
  out.stretch.resize(n);
  out.axis.resize(n);
  parallelFor(0, int((n + kChunk - 1) / kChunk), [&](int c) {
    const std::size_t e = std::min(n, std::size_t(c + 1) * kChunk);
    for (std::size_t m = std::size_t(c) * kChunk; m < e; ++m) {
      const glm::dvec3 p = f.toCamera(glm::dvec3(positions[m]) - f.location);
      const glm::dvec3 v = f.toCamera(glm::dvec3(velocities[m]));
      glm::dvec2 s(v.x, v.y);
      // Perspective: d/dt of the projection, times the depth (see the header).
      if (camera.perspective && p.z < 0.0) s -= glm::dvec2(p.x, p.y) * (v.z / p.z);
      const double speed = glm::length(s);
      const double angle = speed > 0.0 && std::isfinite(speed) ? std::atan2(s.y, s.x) : 0.0;
      out.angle[m] = float(angle);
      out.stretch[m] = float(1.0 + double(stretchFactor) * (std::isfinite(speed) ? speed : 0.0));
      out.axis[m] = glm::vec3(std::cos(angle) * f.right + std::sin(angle) * f.up);
    }
  });
  return out;
}

}  // namespace plume
