#include "nurbs/local_frames.h"

#include "nurbs/evaluation.h"
#include "nurbs/knots.h"

#include <algorithm>
#include <cmath>

namespace plume {
namespace {

/// What "vanishes" is measured against: 1e-9 of the net's size (world units).
double vanishing(const NurbsSurface& s) {
  glm::dvec3 lo(s.controlPoints.front()), hi(lo);
  for (const glm::vec4& p : s.controlPoints) {
    lo = glm::min(lo, glm::dvec3(p));
    hi = glm::max(hi, glm::dvec3(p));
  }
  return 1e-9 * std::max(glm::length(hi - lo), 1e-30);
}

LocalFrame frameAt(const NurbsSurface& s, const SurfaceKnots& k, double u, double v, double tiny) {
  const SurfaceDomain dom{blenderDomain(k.u, s.nu, s.orderU), blenderDomain(k.v, s.nv, s.orderV)};
  u = std::clamp(u, double(dom.u.start), double(dom.u.end));
  v = std::clamp(v, double(dom.v.start), double(dom.v.end));
  const double cu = 0.5 * (double(dom.u.start) + double(dom.u.end));
  const double cv = 0.5 * (double(dom.v.start) + double(dom.v.end));
  for (double f : {0.0, 1e-4, 1e-2}) {
    const SurfaceDerivatives d = surfaceDerivatives(s, k, u + f * (cu - u), v + f * (cv - v));
    const double lu = glm::length(d.du), lv = glm::length(d.dv);
    const glm::dvec3 n = glm::cross(d.du, d.dv);
    const double ln = glm::length(n);
    if (!(lu > tiny) || !(lv > tiny) || !(ln > 1e-9 * lu * lv)) continue;
    LocalFrame frame;
    frame.tangent = d.du / lu;
    frame.normal = n / ln;
    frame.binormal = glm::cross(frame.normal, frame.tangent);
    frame.valid = true;
    return frame;
  }
  return LocalFrame{};
}

}  // namespace

LocalFrame surfaceFrame(const NurbsSurface& s, const SurfaceKnots& k, double u, double v) {
  s.validate();
  return frameAt(s, k, u, v, vanishing(s));
}

std::vector<LocalFrame> controlPointFrames(const NurbsSurface& s) {
  s.validate();
  const SurfaceKnots k = surfaceKnots(s);
  const std::vector<double> gu = grevilleAbscissae(k.u, s.nu, s.orderU);
  const std::vector<double> gv = grevilleAbscissae(k.v, s.nv, s.orderV);
  const double tiny = vanishing(s);
  std::vector<LocalFrame> out(s.controlPoints.size());
  for (int j = 0; j < s.nv; ++j)
    for (int i = 0; i < s.nu; ++i)
      out[std::size_t(j) * std::size_t(s.nu) + std::size_t(i)] =
          frameAt(s, k, gu[std::size_t(i)], gv[std::size_t(j)], tiny);
  return out;
}

}  // namespace plume
