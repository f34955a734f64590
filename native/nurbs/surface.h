#pragma once
/// \file surface.h
/// The NURBS surface of one streakline cluster ([Smoke Surfaces] §3.3, Figure 6) as plain data,
/// laid out exactly like a Blender SURFACE spline so the add-on copies it with one foreach_set.

#include "nurbs/knots.h"

#include <glm/glm.hpp>

#include <vector>

namespace plume {

/// Order and knot type per direction, as a Blender spline stores them (order_u/v,
/// use_endpoint_u/v). u runs along a streakline (particle birth order), v across the ordered
/// streaklines (§3.3).
struct SurfaceSpec {
  int orderU = 4;          ///< requested order along u; the surface uses min(orderU, nu)
  int orderV = 4;          ///< requested order along v; the surface uses min(orderV, nv)
  bool endpointU = true;   ///< Blender's "Endpoint" (clamped knots) along u
  bool endpointV = true;   ///< Blender's "Endpoint" (clamped knots) along v

  /// Throws std::invalid_argument unless both orders are in [2, 6] (Blender's order range).
  void validate() const;
};

/// A NURBS surface with nu × nv control points in Blender's flat order
/// controlPoints[v * nu + u] = (x, y, z, w) (BPoint.vec; x, y, z are not premultiplied by w).
struct NurbsSurface {
  int nu = 0;
  int nv = 0;
  int orderU = 2;
  int orderV = 2;
  bool endpointU = true;
  bool endpointV = true;
  std::vector<glm::vec4> controlPoints;

  /// Throws std::invalid_argument unless Blender can draw it (BKE_nurb_check_valid_uv: nu, nv
  /// >= 2, 2 <= order <= min(6, n)), the point count is nu * nv and weights are > 0 and finite.
  void validate() const;
  const glm::vec4& point(int u, int v) const { return controlPoints[std::size_t(v) * nu + u]; }
};

/// Blender's knot vectors of a surface, computed once for repeated evaluation.
struct SurfaceKnots {
  std::vector<float> u;
  std::vector<float> v;
};
SurfaceKnots surfaceKnots(const NurbsSurface& surface);

/// The rectangle of parameters Blender draws: blenderDomain() in u and in v.
struct SurfaceDomain {
  KnotDomain u;
  KnotDomain v;
};
SurfaceDomain surfaceDomain(const NurbsSurface& surface);

}  // namespace plume
