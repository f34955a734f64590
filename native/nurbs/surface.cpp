#include "nurbs/surface.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

void checkOrder(const char* name, int order) {
  if (order < kMinBlenderOrder || order > kMaxBlenderOrder) {
    std::ostringstream s;
    s << name << " must be in [" << kMinBlenderOrder << ", " << kMaxBlenderOrder << "] (got "
      << order << ")";
    throw std::invalid_argument(s.str());
  }
}

void checkCount(const char* name, int count, const char* orderName, int order) {
  if (count < 2) {
    std::ostringstream s;
    s << name << " must be at least 2 control points (got " << count << ")";
    throw std::invalid_argument(s.str());
  }
  if (order > count) {
    std::ostringstream s;
    s << orderName << " must be in [" << kMinBlenderOrder << ", " << count << "] for " << name
      << " = " << count << " (got " << order << ")";
    throw std::invalid_argument(s.str());
  }
}

}  // namespace

void SurfaceSpec::validate() const {
  checkOrder("order_u", orderU);
  checkOrder("order_v", orderV);
}

void NurbsSurface::validate() const {
  checkOrder("order_u", orderU);
  checkOrder("order_v", orderV);
  checkCount("nu", nu, "order_u", orderU);
  checkCount("nv", nv, "order_v", orderV);
  if (controlPoints.size() != std::size_t(nu) * std::size_t(nv)) {
    std::ostringstream s;
    s << "control_points must have nu * nv = " << std::size_t(nu) * std::size_t(nv)
      << " points (got " << controlPoints.size() << ")";
    throw std::invalid_argument(s.str());
  }
  for (const glm::vec4& p : controlPoints) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw std::invalid_argument("control_points must be finite");
    if (!(p.w > 0.f) || !std::isfinite(p.w))
      throw std::invalid_argument("control point weights must be finite and > 0");
  }
}

SurfaceKnots surfaceKnots(const NurbsSurface& s) {
  return {blenderKnots(s.nu, s.orderU, s.endpointU), blenderKnots(s.nv, s.orderV, s.endpointV)};
}

SurfaceDomain surfaceDomain(const NurbsSurface& s) {
  const SurfaceKnots k = surfaceKnots(s);
  return {blenderDomain(k.u, s.nu, s.orderU), blenderDomain(k.v, s.nv, s.orderV)};
}

}  // namespace plume
