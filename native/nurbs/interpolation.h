#pragma once
/// \file interpolation.h
/// The NURBS surface through every particle of a streakline cluster ([Smoke Surfaces] §3.3,
/// Figure 6): tensor-product B-spline interpolation on Blender's knots.

#include "nurbs/surface.h"

#include <glm/glm.hpp>

#include <vector>

namespace plume {

/// One direction's interpolation (the 1-D step of §3.3): replaces the `pointCount` data points in
/// `values` by the control points c_j with Σ_j N_j(τ_i) c_j = q_i at the interpolation parameters
/// τ_i = interpolationParameters(pointCount, order, endpoint). The collocation matrix is banded
/// (row i has `order` non-zeros) and solved by BandedLu.
void interpolateCurve(std::vector<glm::dvec3>& values, int pointCount, int order, bool endpoint);

/// §3.3: control points P (weights 1: a B-spline surface) such that S(τ_a, σ_b) = Q[b * nu + a]
/// at the interpolation parameters of both directions (the Greville abscissae of Blender's
/// knots, mapped onto the drawn domain). Q[v][u]: u = particle birth order along a streakline,
/// v = ordered streaklines; nu particles per streakline, nv streaklines.
///
/// Tensor product: the 1-D system along u is solved for every streakline, then the one along v
/// for every column. Orders are min(spec.order, n). A direction with a single data point gets
/// two equal control points of order 2 (Blender draws no spline with fewer than 2 points,
/// BKE_nurb_check_valid_u), so the surface is constant along it and passes through the point.
/// Throws std::invalid_argument for bad counts, orders or non-finite points.
NurbsSurface interpolateSurface(const std::vector<glm::vec3>& Q, int nu, int nv,
                                const SurfaceSpec& spec = {});

/// The interpolation parameters (τ_a in u, σ_b in v) a surface made by interpolateSurface() uses
/// for its particles: interpolationParameters() of each direction.
struct SurfaceParameters {
  std::vector<double> u;
  std::vector<double> v;
};
SurfaceParameters particleParameters(const NurbsSurface& surface);

}  // namespace plume
