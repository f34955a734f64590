/// \file bind_nurbs_fit.cpp
/// The least-squares streak surface ([Smoke Surfaces] §3.3 with a control net an artist can
/// edit) for Python: one frame's fit, a whole shot's fit with the net size chosen for a
/// tolerance, and the local frames at the control points that hand edits are kept in.

#include "bindings/bindings.h"
#include "bindings/nurbs_convert.h"

#include "nurbs/local_frames.h"
#include "nurbs/shot_fit.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace py = pybind11;

namespace plume::bindings {
namespace {

using namespace nurbs_convert;

using KeepArray = UInt8ArrayC;

/// Frames of points (frames, lines, particles, 3) float32 and keep flags (frames, lines,
/// particles) as StreakGrids that point into both arrays (kept alive by the caller).
std::vector<StreakGrid> shotFrom(const FloatArrayC& a, const KeepArray& keep) {
  if (a.ndim() != 4 || a.shape(3) != 3 || a.shape(0) < 1 || a.shape(1) < 1 || a.shape(2) < 1)
    throw py::value_error("points must have shape (frames, lines, particles, 3) with every size "
                          ">= 1, got " + shapeText(a));
  if (keep.ndim() != 3 || keep.shape(0) != a.shape(0) || keep.shape(1) != a.shape(1) ||
      keep.shape(2) != a.shape(2))
    throw py::value_error("keep must have shape (frames, lines, particles) of points " +
                          shapeText(a) + ", got " + shapeText(keep));
  std::vector<StreakGrid> frames(std::size_t(a.shape(0)));
  const std::size_t perFrame = std::size_t(a.shape(1) * a.shape(2));
  const glm::vec3* base = reinterpret_cast<const glm::vec3*>(a.data());
  for (std::size_t f = 0; f < frames.size(); ++f)
    frames[f] = StreakGrid{base + f * perFrame, keep.data() + f * perFrame, int(a.shape(2)),
                           int(a.shape(1))};
  return frames;
}

/// A frame's particle parameters u as (lines, particles) float64 (NaN where not kept).
py::array_t<double> paramsArray(const SurfaceFit& f, int lines, int particles) {
  py::array_t<double> a({py::ssize_t(lines), py::ssize_t(particles)});
  std::memcpy(a.mutable_data(), f.paramsU.data(), f.paramsU.size() * sizeof(double));
  return a;
}

/// A fitted surface's dict: surfaceDict() with the particles' own parameters and the residual.
py::dict fitDict(const SurfaceFit& f, int lines, int particles) {
  py::dict d = surfaceDict(f.surface);
  d["params_u"] = paramsArray(f, lines, particles);
  d["params_v"] = array1D(f.paramsV);
  d["max_residual"] = f.maxResidual;
  d["net_deviation"] = f.netDeviation;
  d["net_to_particles"] = f.netToParticles;
  return d;
}

}  // namespace

void bindNurbsFit(py::module_& m) {
  m.def(
      "fit_surface",
      [](const FloatArrayC& points, const py::object& keepObj, int nu, int nv, int orderU, int orderV,
         double smoothing, double exponentU, double exponentV) {
        if (points.ndim() != 3 || points.shape(2) != 3 || points.shape(0) < 1 || points.shape(1) < 1)
          throw py::value_error("points must have shape (lines, particles, 3) with lines, particles "
                                ">= 1, got " + shapeText(points));
        const py::ssize_t lines = points.shape(0), particles = points.shape(1);
        KeepArray keep =
            keepObj.is_none() ? KeepArray({lines, particles}) : KeepArray::ensure(keepObj);
        if (!keep || keep.ndim() != 2 || keep.shape(0) != lines || keep.shape(1) != particles)
          throw py::value_error("keep must be flags of shape (lines, particles) of points " +
                                shapeText(points));
        if (keepObj.is_none()) std::fill_n(keep.mutable_data(), keep.size(), std::uint8_t(1));
        const StreakGrid g{reinterpret_cast<const glm::vec3*>(points.data()), keep.data(),
                           int(particles), int(lines)};
        SurfaceFitParams p;
        p.orderU = orderU;
        p.orderV = orderV;
        p.smoothing = smoothing;
        p.exponentU = exponentU;
        p.exponentV = exponentV;
        SurfaceFit f;
        {
          py::gil_scoped_release release;
          f = fitSurface(g, nu, nv, p);
        }
        return fitDict(f, int(lines), int(particles));
      },
      py::arg("points"), py::arg("keep") = py::none(), py::arg("nu"), py::arg("nv"),
      py::arg("order_u") = 4, py::arg("order_v") = 4,
      py::arg("smoothing") = SurfaceFitParams{}.smoothing,
      py::arg("exponent_u") = SurfaceFitParams{}.exponentU,
      py::arg("exponent_v") = SurfaceFitParams{}.exponentV,
      "§3.3 as a least-squares fit: the B-spline surface (endpoint knots, weights 1) with an "
      "nu x nv control net nearest to points (lines, particles, 3) — u along a streakline, oldest first, "
      "v across the ordered streaklines — through the particles flagged in keep (lines, particles) "
      "(None: all). Each line at its own chord-length parameters, the lines at averaged chord "
      "length, a second-difference penalty of relative weight `smoothing`. Returns the "
      "interpolate_surface dict with params_u (lines, particles) (NaN where not kept) / params_v "
      "(lines,) = the particles' parameters, max_residual = max |S(u_ab, v_b) - q_ab| and "
      "net_deviation = max |P_ij - S(greville_i, greville_j)|, net_to_particles = the largest "
      "distance from a control point to the nearest kept particle.");
  m.def(
      "fit_streak_shot",
      [](const FloatArrayC& points, const KeepArray& keep, double tolerance, double netTolerance,
         double particleTolerance, int orderU, int orderV, double smoothing, double exponentU,
         double exponentV, int nu, int nv, bool particleNetU, bool particleNetV) {
        const std::vector<StreakGrid> frames = shotFrom(points, keep);
        ShotFitParams p;
        p.fit.orderU = orderU;
        p.fit.orderV = orderV;
        p.fit.smoothing = smoothing;
        p.fit.exponentU = exponentU;
        p.fit.exponentV = exponentV;
        p.tolerance = tolerance;
        p.netTolerance = netTolerance;
        p.particleTolerance = particleTolerance;
        NetSize size;
        std::vector<SurfaceFit> fits;
        {
          py::gil_scoped_release release;
          p.validate();
          if (nu > 0 && nv > 0) {
            size.nu = nu;
            size.nv = nv;
            size.orderU = orderU;
            size.orderV = orderV;
            size.particleNetU = particleNetU;
            size.particleNetV = particleNetV;
          } else {
            size = chooseNetSize(frames, p);
          }
          fits = fitShot(frames, size, p.fit);
        }
        const NurbsSurface& s0 = fits.front().surface;
        py::array_t<float> cps({py::ssize_t(fits.size()), py::ssize_t(s0.controlPoints.size()),
                                py::ssize_t(4)});
        const py::ssize_t count = py::ssize_t(fits.size());
        py::array_t<double> residual(count), deviation(count), toParticles(count);
        py::list paramsU, paramsV;
        for (std::size_t f = 0; f < fits.size(); ++f) {
          std::memcpy(cps.mutable_data(py::ssize_t(f)), fits[f].surface.controlPoints.data(),
                      s0.controlPoints.size() * sizeof(glm::vec4));
          residual.mutable_data()[f] = fits[f].maxResidual;
          deviation.mutable_data()[f] = fits[f].netDeviation;
          toParticles.mutable_data()[f] = fits[f].netToParticles;
          paramsU.append(paramsArray(fits[f], frames[f].lines, frames[f].particles));
          paramsV.append(array1D(fits[f].paramsV));
        }
        py::dict d;
        d["nu"] = s0.nu;
        d["nv"] = s0.nv;
        d["order_u"] = s0.orderU;
        d["order_v"] = s0.orderV;
        d["particle_net_u"] = size.particleNetU;
        d["particle_net_v"] = size.particleNetV;
        d["control_points"] = cps;
        d["params_u"] = paramsU;
        d["params_v"] = paramsV;
        d["max_residual"] = residual;
        d["net_deviation"] = deviation;
        d["net_to_particles"] = toParticles;
        return d;
      },
      py::arg("points"), py::arg("keep"), py::arg("tolerance"), py::arg("net_tolerance"),
      py::arg("particle_tolerance") = ShotFitParams{}.particleTolerance, py::arg("order_u") = 4,
      py::arg("order_v") = 4, py::arg("smoothing") = SurfaceFitParams{}.smoothing,
      py::arg("exponent_u") = SurfaceFitParams{}.exponentU,
      py::arg("exponent_v") = SurfaceFitParams{}.exponentV, py::arg("nu") = 0, py::arg("nv") = 0,
      py::arg("particle_net_u") = false, py::arg("particle_net_v") = false,
      "§3.3 for a whole shot: points (frames, lines, particles, 3) float32 and keep (frames, "
      "lines, particles), the particles each frame's sheet goes through (as fit_surface). Chooses "
      "the smallest control net nu x nv (fixed for the shot, as Blender's net is; for crumpled "
      "clusters across the lines, and for scattered lines along them, the order may drop to 3, "
      "then the particle net: the control points are the particles, or the lines' curves, at "
      "the first order, with the sheet within `particle_tolerance` of them (particle_net_u / "
      "particle_net_v True), then order 2) that keeps every kept particle "
      "within `tolerance` (world units) of every frame's sheet, every control point within "
      "`net_tolerance` of the sheet at its Greville abscissae and within `particle_tolerance` "
      "of the nearest kept particle — or uses nu, nv, order_u, order_v, particle_net_u, "
      "particle_net_v when nu and nv are > 0 — and fits every frame with it. Returns dict(nu, nv, order_u, "
      "order_v, particle_net_u, particle_net_v, control_points float32 (frames, nv*nu, 4) in Blender's flat order, params_u / "
      "params_v: per frame the particles' parameters (NaN where not kept), max_residual, "
      "net_deviation, net_to_particles (distance from the farthest control point to its nearest "
      "kept particle): float64 (frames,)). ValueError on bad input.");
  m.def(
      "control_point_frames",
      [](const py::dict& surface) {
        const NurbsSurface s = surfaceFrom(surface);
        const std::vector<LocalFrame> frames = controlPointFrames(s);
        py::array_t<double> axes({py::ssize_t(frames.size()), py::ssize_t(3), py::ssize_t(3)});
        py::array_t<bool> valid(py::ssize_t(frames.size()));
        double* a = axes.mutable_data();
        for (std::size_t n = 0; n < frames.size(); ++n) {
          const glm::dvec3* rows[3] = {&frames[n].tangent, &frames[n].binormal, &frames[n].normal};
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
              a[n * 9 + std::size_t(r) * 3 + std::size_t(c)] = (*rows[r])[c];
          valid.mutable_data()[n] = frames[n].valid;
        }
        return py::make_tuple(axes, valid);
      },
      py::arg("surface"),
      "Local frames at the control points (each at its Greville abscissae; hand edits turn with "
      "them): (axes float64 (nu*nv, 3, 3) with rows tangent S_u, binormal n x t, normal "
      "S_u x S_v, all unit; valid bool (nu*nv,), False where the sheet has no tangent plane and "
      "the axes are the world's).");
}

}  // namespace plume::bindings
