#pragma once
/// \file local_frames.h
/// Local frames of a streak surface at its control points, for hand edits that turn with the
/// sheet ([Smoke Surfaces] §5, Figure 13: the artist warps the NURBS surface; the add-on keeps
/// the warp as offsets in these frames and applies them on every frame).

#include "nurbs/surface.h"

#include <glm/glm.hpp>

#include <vector>

namespace plume {

/// An orthonormal frame on the surface: tangent t = S_u / |S_u| (along the streaklines),
/// normal n = (S_u × S_v) / |S_u × S_v|, binormal b = n × t (across them, in the tangent plane).
/// `valid` is false where the surface has no tangent plane (a sheet collapsed to a curve or a
/// point); the frame is then the world axes (x, y, z).
struct LocalFrame {
  glm::dvec3 tangent{1.0, 0.0, 0.0};
  glm::dvec3 binormal{0.0, 1.0, 0.0};
  glm::dvec3 normal{0.0, 0.0, 1.0};
  bool valid = false;
};

/// The frame at (u, v), clamped to the drawn domain. Where S_u or S_u × S_v vanishes (a
/// collapsed edge) it is taken a little towards the domain centre, as surfaceNormal() does.
LocalFrame surfaceFrame(const NurbsSurface& surface, const SurfaceKnots& knots, double u, double v);

/// surfaceFrame() at every control point's Greville abscissae (ḡ_i along u, ḡ_j along v, inside
/// the drawn domain for endpoint knots; clamped to it for uniform ones), in Blender's flat
/// order [j * nu + i]. Throws std::invalid_argument if the surface is not valid.
std::vector<LocalFrame> controlPointFrames(const NurbsSurface& surface);

}  // namespace plume
