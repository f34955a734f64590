#pragma once
/// \file nurbs_convert.h
/// Conversions shared by the NURBS bindings (bind_nurbs.cpp, bind_nurbs_fit.cpp): the surface
/// dict <-> the core's NurbsSurface, control points, point grids and density grids (the
/// conversions of every component are in convert.h).

#include "bindings/convert.h"
#include "core/grid3.h"
#include "nurbs/evaluation.h"
#include "nurbs/interpolation.h"
#include "nurbs/surface.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <glm/glm.hpp>

#include <cmath>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

namespace plume::bindings {
namespace nurbs_convert {

inline py::dict surfaceDict(const NurbsSurface& s) {
  py::dict d;
  d["control_points"] = rowsArray(s.controlPoints);
  d["nu"] = s.nu;
  d["nv"] = s.nv;
  d["order_u"] = s.orderU;
  d["order_v"] = s.orderV;
  d["endpoint_u"] = s.endpointU;
  d["endpoint_v"] = s.endpointV;
  const SurfaceKnots k = surfaceKnots(s);
  const SurfaceDomain dom = surfaceDomain(s);
  const SurfaceParameters p = particleParameters(s);
  d["knots_u"] = array1D(k.u);
  d["knots_v"] = array1D(k.v);
  d["domain_u"] = py::make_tuple(dom.u.start, dom.u.end);
  d["domain_v"] = py::make_tuple(dom.v.start, dom.v.end);
  d["params_u"] = array1D(p.u);
  d["params_v"] = array1D(p.v);
  return d;
}

/// Control points given as (nu * nv, 3|4) or (nv, nu, 3|4); w = 1 when absent.
inline std::vector<glm::vec4> controlPointsFrom(const py::handle& obj, int nu, int nv) {
  const FloatArrayC a = FloatArrayC::ensure(obj);
  if (!a) throw py::value_error("control_points must be a float array");
  const py::ssize_t comps = a.ndim() >= 1 ? a.shape(a.ndim() - 1) : 0;
  const py::ssize_t count = comps > 0 ? a.size() / comps : 0;
  if ((a.ndim() != 2 && a.ndim() != 3) || (comps != 3 && comps != 4) ||
      count != py::ssize_t(nu) * nv) {
    std::ostringstream s;
    s << "control_points must have shape (nu * nv, 4) or (nu * nv, 3) with nu * nv = "
      << py::ssize_t(nu) * nv << ", got " << shapeText(a);
    throw py::value_error(s.str());
  }
  std::vector<glm::vec4> out(static_cast<std::size_t>(count));
  const float* d = a.data();
  for (py::ssize_t n = 0; n < count; ++n)
    out[std::size_t(n)] = glm::vec4(d[n * comps], d[n * comps + 1], d[n * comps + 2],
                                    comps == 4 ? d[n * comps + 3] : 1.f);
  return out;
}

inline NurbsSurface surfaceFrom(const py::dict& d) {
  for (const char* key : {"control_points", "nu", "nv", "order_u", "order_v"})
    if (!d.contains(key)) throw py::value_error(std::string("surface dict needs '") + key + "'");
  NurbsSurface s;
  s.nu = d["nu"].cast<int>();
  s.nv = d["nv"].cast<int>();
  s.orderU = d["order_u"].cast<int>();
  s.orderV = d["order_v"].cast<int>();
  s.endpointU = d.contains("endpoint_u") ? d["endpoint_u"].cast<bool>() : true;
  s.endpointV = d.contains("endpoint_v") ? d["endpoint_v"].cast<bool>() : true;
  s.controlPoints = controlPointsFrom(d["control_points"], s.nu, s.nv);
  s.validate();
  return s;
}

/// Points (nv, nu, 3): Q[v][u], u along a streakline, v across streaklines.
inline std::vector<glm::vec3> gridPointsFrom(const DoubleArrayC& a, int& nu, int& nv) {
  if (a.ndim() != 3 || a.shape(2) != 3 || a.shape(0) < 1 || a.shape(1) < 1)
    throw py::value_error("points must have shape (nv, nu, 3) with nv, nu >= 1, got " + shapeText(a));
  nv = int(a.shape(0));
  nu = int(a.shape(1));
  std::vector<glm::vec3> q(std::size_t(nu) * std::size_t(nv));
  const double* d = a.data();
  for (std::size_t n = 0; n < q.size(); ++n) q[n] = glm::vec3(d[3 * n], d[3 * n + 1], d[3 * n + 2]);
  return q;
}

inline ScalarGrid gridFrom(const py::handle& obj) {
  const FloatArrayF a = FloatArrayF::ensure(obj);
  if (!a || a.ndim() != 3 || a.shape(0) < 1 || a.shape(1) < 1 || a.shape(2) < 1)
    throw py::value_error("density must be a float array of shape (nx, ny, nz)");
  ScalarGrid g({int(a.shape(0)), int(a.shape(1)), int(a.shape(2))});
  std::memcpy(g.data(), a.data(), g.count() * sizeof(float));  // Fortran order = x fastest
  for (std::size_t n = 0; n < g.count(); ++n)
    if (!std::isfinite(g[n])) throw py::value_error("density contains NaN or inf");
  return g;
}

}  // namespace nurbs_convert
}  // namespace plume::bindings
