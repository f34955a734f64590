#pragma once
/// \file evaluation.h
/// Points, derivatives and normals of a streak surface ([Smoke Surfaces] §3.3-3.4: the opacity
/// p = d·e^(−|n·v|) needs the normal n), and the vertex grid Blender 3.4 tessellates.
/// Parameters are Blender's knot parameters; they are clamped to the drawn domain
/// (surfaceDomain()), where Blender's own sampling stays.

#include "nurbs/surface.h"

#include <glm/glm.hpp>

#include <vector>

namespace plume {

/// S(u, v) = Σ N_i(u) N_j(v) w_ij P_ij / Σ N_i(u) N_j(v) w_ij (evaluated in double).
glm::vec3 surfacePoint(const NurbsSurface& surface, double u, double v);
/// Same, with the knots computed once by surfaceKnots().
glm::vec3 surfacePoint(const NurbsSurface& surface, const SurfaceKnots& knots, double u, double v);

/// S and its first partial derivatives ∂S/∂u, ∂S/∂v (rational quotient rule).
struct SurfaceDerivatives {
  glm::dvec3 point{0.0};
  glm::dvec3 du{0.0};
  glm::dvec3 dv{0.0};
};
SurfaceDerivatives surfaceDerivatives(const NurbsSurface& surface, const SurfaceKnots& knots,
                                      double u, double v);

/// Unit normal (∂S/∂u × ∂S/∂v) / |…|. Where the surface is degenerate (a collapsed edge or
/// corner) the normal is taken a little inside the domain; where it has no normal at all (a
/// single particle per streakline makes a curve) it is (0, 0, 0).
glm::vec3 surfaceNormal(const NurbsSurface& surface, double u, double v);
glm::vec3 surfaceNormal(const NurbsSurface& surface, const SurfaceKnots& knots, double u, double v);

/// S at every (us[a], vs[b]), row-major v then u: result[b * us.size() + a]. One basis
/// evaluation per parameter, O(order) per point; rows in parallel (deterministic).
std::vector<glm::vec3> surfaceGrid(const NurbsSurface& surface, const std::vector<double>& us,
                                   const std::vector<double>& vs);

/// The vertex grid Blender 3.4 makes for a SURFACE object (BKE_nurb_makeFaces, called from
/// displist.cc's evaluate_surface with the spline's resolution_u/v): countU = nu * resolutionU
/// samples blenderSamples() in u, countV = nv * resolutionV in v, in Blender's order
/// vertices[iu * countV + iv] (the u loop is the outer one; DL_SURF parts = countU, nr = countV),
/// which is the vertex order of the object's evaluated mesh.
struct TessellatedSurface {
  int countU = 0;
  int countV = 0;
  std::vector<glm::vec3> vertices;
};
TessellatedSurface tessellate(const NurbsSurface& surface, int resolutionU, int resolutionV);

}  // namespace plume
