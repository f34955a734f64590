/// \file bind_nurbs.cpp
/// Streak-surface NURBS ([Smoke Surfaces] §3.3-3.4) for Python: interpolation on Blender's
/// knots, evaluation, Blender's tessellation, the density map and the OpenSubdiv mesh export.
/// A "surface" is the dict interpolate_surface() returns (control_points, nu, nv, order_u,
/// order_v, endpoint_u, endpoint_v); the add-on can build one from a Blender spline too.

#include "bindings/bindings.h"
#include "bindings/nurbs_convert.h"

#include "nurbs/density_map.h"
#include "nurbs/evaluation.h"
#include "nurbs/interpolation.h"
#include "nurbs/knots.h"
#include "nurbs/subdivision_export.h"

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstring>
#include <sstream>

namespace py = pybind11;

namespace plume::bindings {
namespace {

using namespace nurbs_convert;

/// Evaluates f(u, v) -> vec3 over broadcast u, v arrays; result shape u.shape + (3,).
template <typename F>
py::array_t<float> evaluateAt(const py::handle& uObj, const py::handle& vObj, F f) {
  py::module_ np = py::module_::import("numpy");
  py::tuple b = np.attr("broadcast_arrays")(np.attr("asarray")(uObj, "float64"),
                                            np.attr("asarray")(vObj, "float64"));
  const DoubleArrayC u = DoubleArrayC::ensure(b[0]), v = DoubleArrayC::ensure(b[1]);
  std::vector<py::ssize_t> shape(u.shape(), u.shape() + u.ndim());
  shape.push_back(3);
  py::array_t<float> out(shape);
  float* o = out.mutable_data();
  const double* pu = u.data();
  const double* pv = v.data();
  for (py::ssize_t n = 0; n < u.size(); ++n) {
    const glm::vec3 p = f(pu[n], pv[n]);
    o[3 * n] = p.x;
    o[3 * n + 1] = p.y;
    o[3 * n + 2] = p.z;
  }
  return out;
}

/// A density map as a (height, width) float32 image, row = v, column = u.
py::array_t<float> mapArray(const DensityMap& map) {
  py::array_t<float> a({py::ssize_t(map.height), py::ssize_t(map.width)});
  std::memcpy(a.mutable_data(), map.values.data(), map.values.size() * sizeof(float));
  return a;
}

}  // namespace

void bindNurbs(py::module_& m) {
  m.def("nurbs_knots", [](int n, int order, bool endpoint) { return array1D(blenderKnots(n, order, endpoint)); },
        py::arg("point_count"), py::arg("order"), py::arg("endpoint") = true,
        "Blender 3.4's knot vector (curve.cc calcknots) for point_count points of this order, "
        "endpoint (clamped) or uniform: float32 array of point_count + order knots.");
  m.def(
      "nurbs_domain",
      [](int n, int order, bool endpoint) {
        const KnotDomain d = blenderDomain(blenderKnots(n, order, endpoint), n, order);
        return py::make_tuple(d.start, d.end);
      },
      py::arg("point_count"), py::arg("order"), py::arg("endpoint") = true,
      "(start, end): the parameter interval Blender draws, [knots[order-1], knots[point_count]].");
  m.def("nurbs_samples",
        [](int n, int order, bool endpoint, int resolution) {
          return array1D(blenderSamples(n, order, endpoint, resolution));
        },
        py::arg("point_count"), py::arg("order"), py::arg("endpoint"), py::arg("resolution"),
        "The point_count * resolution parameters BKE_nurb_makeFaces samples (float32, as Blender).");
  m.def(
      "greville_abscissae",
      [](int n, int order, bool endpoint) {
        return array1D(grevilleAbscissae(blenderKnots(n, order, endpoint), n, order));
      },
      py::arg("point_count"), py::arg("order"), py::arg("endpoint") = true,
      "Greville abscissae of Blender's knots (float64).");
  m.def("interpolation_parameters",
        [](int n, int order, bool endpoint) { return array1D(interpolationParameters(n, order, endpoint)); },
        py::arg("point_count"), py::arg("order"), py::arg("endpoint") = true,
        "Parameters of the particles (§3.3): Greville abscissae mapped onto the drawn interval.");
  m.def("supersample_parameters",
        [](const std::vector<double>& nodes, int rate) { return array1D(supersampleParameters(nodes, rate)); },
        py::arg("nodes"), py::arg("rate"),
        "§3.4: the nodes plus `rate` evenly spaced parameters between consecutive ones.");

  m.def(
      "interpolate_surface",
      [](const DoubleArrayC& points, int orderU, int orderV, bool endpointU, bool endpointV) {
        int nu = 0, nv = 0;
        const std::vector<glm::vec3> q = gridPointsFrom(points, nu, nv);
        SurfaceSpec spec;
        spec.orderU = orderU;
        spec.orderV = orderV;
        spec.endpointU = endpointU;
        spec.endpointV = endpointV;
        NurbsSurface s;
        {
          py::gil_scoped_release release;
          s = interpolateSurface(q, nu, nv, spec);
        }
        return surfaceDict(s);
      },
      py::arg("points"), py::arg("order_u") = 4, py::arg("order_v") = 4, py::arg("endpoint_u") = true,
      py::arg("endpoint_v") = true,
      "§3.3: the B-spline surface (weights 1) through points (nv, nu, 3) — u along a streakline "
      "(birth order), v across the ordered streaklines — on Blender's knots, interpolated at the "
      "Greville abscissae. Returns dict(control_points float32 (nv*nu, 4) in Blender's flat order "
      "points[v*nu+u] = (x, y, z, w), nu, nv (control net; a single point in a direction gives "
      "2 equal control points), order_u, order_v (min(order, n)), endpoint_u, endpoint_v, knots_u, "
      "knots_v, domain_u, domain_v, params_u, params_v (parameters of the particles)). "
      "ValueError on bad input.");
  m.def(
      "surface_point",
      [](const py::dict& surface, const py::object& u, const py::object& v) {
        const NurbsSurface s = surfaceFrom(surface);
        const SurfaceKnots k = surfaceKnots(s);
        return evaluateAt(u, v, [&](double a, double b) { return surfacePoint(s, k, a, b); });
      },
      py::arg("surface"), py::arg("u"), py::arg("v"),
      "S(u, v) at Blender parameters (broadcast arrays or scalars; clamped to the drawn domain): "
      "float32 array of shape broadcast(u, v).shape + (3,).");
  m.def(
      "surface_normal",
      [](const py::dict& surface, const py::object& u, const py::object& v) {
        const NurbsSurface s = surfaceFrom(surface);
        const SurfaceKnots k = surfaceKnots(s);
        return evaluateAt(u, v, [&](double a, double b) { return surfaceNormal(s, k, a, b); });
      },
      py::arg("surface"), py::arg("u"), py::arg("v"),
      "Unit normal S_u x S_v / |...| (zero where the surface has none), same shapes as surface_point.");
  m.def(
      "tessellate",
      [](const py::dict& surface, int resolutionU, int resolutionV) {
        const NurbsSurface s = surfaceFrom(surface);
        TessellatedSurface t;
        {
          py::gil_scoped_release release;
          t = tessellate(s, resolutionU, resolutionV);
        }
        py::array_t<float> a({py::ssize_t(t.countU), py::ssize_t(t.countV), py::ssize_t(3)});
        std::memcpy(a.mutable_data(), t.vertices.data(), t.vertices.size() * sizeof(glm::vec3));
        return a;
      },
      py::arg("surface"), py::arg("resolution_u") = 4, py::arg("resolution_v") = 4,
      "The vertex grid Blender 3.4 makes for the SURFACE object (BKE_nurb_makeFaces): float32 "
      "(nu*resolution_u, nv*resolution_v, 3); .reshape(-1, 3) is the evaluated mesh's vertex order.");
  m.def(
      "density_map",
      [](const py::object& surfaceOrPoints, const py::object& density, const py::object& origin,
         float cellSize, int kU, int kV, Interpolation interpolation) {
        NurbsSurface s;
        if (py::isinstance<py::dict>(surfaceOrPoints)) {
          s = surfaceFrom(surfaceOrPoints.cast<py::dict>());
        } else {
          int nu = 0, nv = 0;
          const std::vector<glm::vec3> q = gridPointsFrom(DoubleArrayC::ensure(surfaceOrPoints), nu, nv);
          s = interpolateSurface(q, nu, nv, SurfaceSpec{});
        }
        const ScalarGrid grid = gridFrom(density);
        DensityMapParams p;
        p.samplingU = kU;
        p.samplingV = kV;
        p.interpolation = interpolation;
        p.origin = vec3Arg(origin, "origin", Vec3Form::Array);
        p.cellSize = cellSize;
        DensityMap map;
        {
          py::gil_scoped_release release;
          map = densityMap(s, grid, p);
        }
        return mapArray(map);
      },
      py::arg("surface"), py::arg("density"), py::arg("origin"), py::arg("cell_size"),
      py::arg("k_u") = 4, py::arg("k_v") = 2, py::arg("interpolation") = Interpolation::MonotonicCubic,
      "§3.4 density map: `density` (nx, ny, nz) indexed [i, j, k] (cell centres at origin + "
      "(i+0.5, j+0.5, k+0.5) * cell_size) sampled with `interpolation` on the surface (a surface "
      "dict, or points (nv, nu, 3) interpolated with the defaults) at k_u / k_v samples between "
      "particles. float32 image ((nv-1)(k_v+1)+1, (nu-1)(k_u+1)+1), row = v, column = u.");
  m.def(
      "density_map_on_domain",
      [](const py::dict& surface, const py::object& density, const py::object& origin,
         float cellSize, int width, int height, Interpolation interpolation) {
        const NurbsSurface s = surfaceFrom(surface);
        const ScalarGrid grid = gridFrom(density);
        DensityMapParams p;
        p.interpolation = interpolation;
        p.origin = vec3Arg(origin, "origin", Vec3Form::Array);
        p.cellSize = cellSize;
        DensityMap map;
        {
          py::gil_scoped_release release;
          const SurfaceDomain dom = surfaceDomain(s);
          map = densityMapAt(s, grid, p, evenParameters(dom.u.start, dom.u.end, width),
                             evenParameters(dom.v.start, dom.v.end, height));
        }
        return mapArray(map);
      },
      py::arg("surface"), py::arg("density"), py::arg("origin"), py::arg("cell_size"),
      py::arg("width"), py::arg("height"), py::arg("interpolation") = Interpolation::MonotonicCubic,
      "§3.4 density map on Blender's UV layout: the density sampled (as density_map, 0 outside the "
      "grid's box) at width x height evenly spaced parameters over the drawn domain, float32 "
      "(height, width), row = v, column = u. ValueError for width or height < 2.");
  m.def(
      "density_map_error_1d",
      [](const std::function<double(double)>& field, int particles, int rate, int samples) {
        const DensityMapError e = densityMapError1D(field, particles, rate, samples);
        py::dict d;
        d["rms"] = e.rms;
        d["max"] = e.max;
        return d;
      },
      py::arg("field"), py::arg("particles"), py::arg("rate"), py::arg("evaluation_samples") = 1001,
      "Figure 8 in 1-D: dict(rms, max) error of the linearly interpolated map of field(t), t in "
      "[0, 1], from `particles` particles sampled at `rate` between them.");
  m.def(
      "subdivide_mesh",
      [](const py::object& controlPoints, int nu, int nv, int level, const py::object& density,
         bool limit) {
        const std::vector<glm::vec4> cps = controlPointsFrom(controlPoints, nu, nv);
        std::vector<float> image;
        int width = 0, height = 0;
        if (!density.is_none()) {
          const FloatArrayC d = FloatArrayC::ensure(density);
          if (!d || d.ndim() != 2)
            throw py::value_error("density must be a 2-D density map (rows = v, columns = u)");
          height = int(d.shape(0));
          width = int(d.shape(1));
          image.assign(d.data(), d.data() + d.size());
        }
        SubdivisionParams p;
        p.level = level;
        p.limit = limit;
        SubdividedMesh mesh;
        {
          py::gil_scoped_release release;
          mesh = subdivideControlNet(cps, nu, nv, p, image, width, height);
        }
        py::object dens = py::none();
        if (!mesh.density.empty()) dens = array1D(mesh.density);
        return py::make_tuple(rowsArray(mesh.vertices), rowsArray(mesh.quads), dens);
      },
      py::arg("control_points"), py::arg("nu"), py::arg("nv"), py::arg("level") = 2,
      py::arg("density") = py::none(), py::arg("limit") = true,
      "The control net (nu*nv, 3|4) refined by OpenSubdiv (Catmull-Clark, boundary EDGE_AND_CORNER, "
      "`level` uniform levels, vertices moved to the limit surface when `limit`): (vertices float32 "
      "(N, 3), quads int32 (M, 4), density float32 (N,) read bilinearly from the density map "
      "(shape ((nv-1)(k_v+1)+1, (nu-1)(k_u+1)+1), or (nv, nu) per control point) or None).");
}

}  // namespace plume::bindings
