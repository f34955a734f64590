#include "nurbs/evaluation.h"

#include "core/parallel.h"
#include "nurbs/basis.h"
#include "nurbs/knots.h"

#include <algorithm>
#include <cmath>

namespace plume {
namespace {

glm::dvec4 homogeneous(const glm::vec4& p) {
  const double w = p.w;
  return {p.x * w, p.y * w, p.z * w, w};
}

/// Σ_ij Nu_i Nv_j Pw_ij for the given basis (values or derivatives) in each direction.
glm::dvec4 weightedSum(const NurbsSurface& s, const BasisValues& bu, const std::vector<double>& nu,
                       const BasisValues& bv, const std::vector<double>& nv) {
  glm::dvec4 sum(0.0);
  for (int j = 0; j < s.orderV; ++j) {
    glm::dvec4 row(0.0);
    for (int i = 0; i < s.orderU; ++i)
      row += nu[std::size_t(i)] * homogeneous(s.point(bu.first + i, bv.first + j));
    sum += nv[std::size_t(j)] * row;
  }
  return sum;
}

}  // namespace

glm::vec3 surfacePoint(const NurbsSurface& s, const SurfaceKnots& k, double u, double v) {
  const BasisValues bu = basisFunctions(k.u, s.nu, s.orderU, u);
  const BasisValues bv = basisFunctions(k.v, s.nv, s.orderV, v);
  const glm::dvec4 a = weightedSum(s, bu, bu.values, bv, bv.values);
  return glm::vec3(glm::dvec3(a) / a.w);
}

glm::vec3 surfacePoint(const NurbsSurface& s, double u, double v) {
  return surfacePoint(s, surfaceKnots(s), u, v);
}

SurfaceDerivatives surfaceDerivatives(const NurbsSurface& s, const SurfaceKnots& k, double u,
                                      double v) {
  const BasisValues bu = basisFunctions(k.u, s.nu, s.orderU, u, /*withDerivatives=*/true);
  const BasisValues bv = basisFunctions(k.v, s.nv, s.orderV, v, /*withDerivatives=*/true);
  const glm::dvec4 a = weightedSum(s, bu, bu.values, bv, bv.values);
  const glm::dvec4 au = weightedSum(s, bu, bu.derivatives, bv, bv.values);
  const glm::dvec4 av = weightedSum(s, bu, bu.values, bv, bv.derivatives);
  SurfaceDerivatives d;
  d.point = glm::dvec3(a) / a.w;
  // Quotient rule for S = A / W: S_u = (A_u - W_u S) / W.
  d.du = (glm::dvec3(au) - au.w * d.point) / a.w;
  d.dv = (glm::dvec3(av) - av.w * d.point) / a.w;
  return d;
}

glm::vec3 surfaceNormal(const NurbsSurface& s, const SurfaceKnots& k, double u, double v) {
  const SurfaceDomain dom{blenderDomain(k.u, s.nu, s.orderU), blenderDomain(k.v, s.nv, s.orderV)};
  u = std::clamp(u, double(dom.u.start), double(dom.u.end));
  v = std::clamp(v, double(dom.v.start), double(dom.v.end));
  const double cu = 0.5 * (double(dom.u.start) + double(dom.u.end));
  const double cv = 0.5 * (double(dom.v.start) + double(dom.v.end));
  // Try the point itself, then points moved towards the domain centre: at a collapsed edge the
  // limit of the normal from inside is the one a renderer interpolates to.
  for (double f : {0.0, 1e-4, 1e-2}) {
    const SurfaceDerivatives d = surfaceDerivatives(s, k, u + f * (cu - u), v + f * (cv - v));
    const glm::dvec3 n = glm::cross(d.du, d.dv);
    const double len = glm::length(n);
    const double scale = glm::length(d.du) * glm::length(d.dv);
    if (len > 1e-12 * std::max(scale, 1e-300) && len > 0.0) return glm::vec3(n / len);
  }
  return glm::vec3(0.f);
}

glm::vec3 surfaceNormal(const NurbsSurface& s, double u, double v) {
  return surfaceNormal(s, surfaceKnots(s), u, v);
}

std::vector<glm::vec3> surfaceGrid(const NurbsSurface& s, const std::vector<double>& us,
                                   const std::vector<double>& vs) {
  s.validate();
  const SurfaceKnots k = surfaceKnots(s);
  const std::size_t nU = us.size(), nV = vs.size();
  std::vector<BasisValues> bu(nU);
  for (std::size_t a = 0; a < nU; ++a) bu[a] = basisFunctions(k.u, s.nu, s.orderU, us[a]);
  std::vector<glm::vec3> out(nU * nV);
  parallelFor(0, int(nV), [&](int b) {
    const BasisValues bv = basisFunctions(k.v, s.nv, s.orderV, vs[std::size_t(b)]);
    // The iso-curve at v: its nu homogeneous control points, then O(order) per sample.
    std::vector<glm::dvec4> curve(std::size_t(s.nu), glm::dvec4(0.0));
    for (int j = 0; j < s.orderV; ++j) {
      const double w = bv.values[std::size_t(j)];
      if (w == 0.0) continue;
      for (int i = 0; i < s.nu; ++i) curve[std::size_t(i)] += w * homogeneous(s.point(i, bv.first + j));
    }
    for (std::size_t a = 0; a < nU; ++a) {
      glm::dvec4 p(0.0);
      for (int i = 0; i < s.orderU; ++i)
        p += bu[a].values[std::size_t(i)] * curve[std::size_t(bu[a].first + i)];
      out[std::size_t(b) * nU + a] = glm::vec3(glm::dvec3(p) / p.w);
    }
  });
  return out;
}

TessellatedSurface tessellate(const NurbsSurface& s, int resolutionU, int resolutionV) {
  s.validate();
  const std::vector<float> fu = blenderSamples(s.nu, s.orderU, s.endpointU, resolutionU);
  const std::vector<float> fv = blenderSamples(s.nv, s.orderV, s.endpointV, resolutionV);
  const std::vector<double> us(fu.begin(), fu.end()), vs(fv.begin(), fv.end());
  const std::vector<glm::vec3> grid = surfaceGrid(s, us, vs);
  TessellatedSurface t;
  t.countU = int(us.size());
  t.countV = int(vs.size());
  t.vertices.resize(grid.size());
  // Blender's order: u outer, v inner.
  for (int b = 0; b < t.countV; ++b)
    for (int a = 0; a < t.countU; ++a)
      t.vertices[std::size_t(a) * t.countV + b] = grid[std::size_t(b) * t.countU + a];
  return t;
}

}  // namespace plume
