#pragma once
/// \file billboard.h
/// Orientation and squash/stretch of the toon stencils ([Cartoon Smoke] §2.3, Figure 4): the
/// stencil faces the camera, its in-plane rotation follows the particle's velocity projected on
/// the image plane, and it stretches along that direction in proportion to the projected speed.
/// Both depend on the camera, so they are computed when the scene is built, not stored.

#include <glm/glm.hpp>

#include <vector>

namespace plume {

/// A Blender camera: its object-to-world matrix (columns: right +x, up +y, backward +z, location;
/// the camera looks down its -z) and whether it is a perspective camera.
struct ToonCamera {
  glm::dmat4 matrixWorld{1.0};
  bool perspective = true;
  /// Throws std::invalid_argument unless the matrix is finite and affine with non-zero axes.
  void validate() const;
};

/// Per particle: in-plane angle (radians, from the camera's +x toward its +y, in (-π, π]; 0 when
/// the projected velocity is 0), stretch = 1 + k |v_screen| and the stencil's stretch axis in
/// world space (cos(angle) right + sin(angle) up).
struct Billboards {
  std::vector<float> angle;
  std::vector<float> stretch;
  std::vector<glm::vec3> axis;
};

/// Figure 4 for every particle. v_screen is the velocity seen in the image plane, in m/s at the
/// particle's depth: orthographic, the velocity's components along the camera's right and up
/// axes; perspective, the time derivative of the projection (x/-z, y/-z) scaled by the depth -z,
/// (v_x - x v_z / z, v_y - y v_z / z) in camera space, so that a stencil's stretch does not
/// depend on its distance (particles at or behind the camera plane use the orthographic form).
/// Throws std::invalid_argument for a bad camera, k < 0 or arrays of different lengths.
Billboards computeBillboards(const ToonCamera& camera, const std::vector<glm::vec3>& positions,
                             const std::vector<glm::vec3>& velocities, float stretchFactor);

}  // namespace plume
