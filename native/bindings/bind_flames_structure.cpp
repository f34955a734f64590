/// \file bind_flames_structure.cpp
/// Structural flames, structure side ([Structural Flames] §4.1–4.3, §6.1–6.2): FlameParams,
/// FlameSource, wind fields, obstacle distance fields, FlameSystem and spine helpers. Conversions
/// and docstrings only; FlameSystem.step releases the GIL.

#include "bindings/bindings.h"
#include "bindings/convert.h"

#include "flames/flame_system.h"
#include "flames/spine.h"

#include <pybind11/stl.h>

#include <memory>

namespace py = pybind11;

namespace plume::bindings {
namespace {

/// An (N, 3) float64 array as points (ValueError otherwise).
std::vector<glm::dvec3> dpointsArg(const py::object& o, const char* name) {
  const DoubleArrayC a = DoubleArrayC::ensure(o);
  if (!a || a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error(std::string(name) + " must be an array of shape (N, 3)");
  std::vector<glm::dvec3> p(std::size_t(a.shape(0)));
  for (py::ssize_t i = 0; i < a.shape(0); ++i) p[std::size_t(i)] = {a.at(i, 0), a.at(i, 1), a.at(i, 2)};
  return p;
}

/// A (nx, ny, nz) float grid from a NumPy array indexed [i, j, k].
ScalarGrid scalarGridArg(const py::object& o, const char* name) {
  const FloatArrayF a = FloatArrayF::ensure(o);
  if (!a || a.ndim() != 3) throw py::value_error(std::string(name) + " must be an array of shape (nx, ny, nz)");
  ScalarGrid g;
  copyGrid(a, glm::ivec3(int(a.shape(0)), int(a.shape(1)), int(a.shape(2))), g, name);
  return g;
}

void bindSettings(py::module_& m) {
  py::enum_<FlameIntegrator>(m, "FlameIntegrator", "Integration of eq. 1 over a step (§4.1).")
      .value("EULER", FlameIntegrator::Euler)
      .value("MIDPOINT", FlameIntegrator::Midpoint)
      .value("RUNGE_KUTTA_4", FlameIntegrator::RungeKutta4);
  py::class_<FlameParams>(m, "FlameParams", "Structure settings of structural flames (§4.1–4.3).")
      .def(py::init<>())
      .def_readwrite("points", &FlameParams::points, "n, control points per spine, in [2, 256]")
      .def_readwrite("height_persistent", &FlameParams::heightPersistent, "H_p (m), in [0, H_i)")
      .def_readwrite("height_intermittent", &FlameParams::heightIntermittent, "H_i (m)")
      .def_readwrite("height_max", &FlameParams::heightMax, "H_max (m), >= H_i: D(h) = 1 past it")
      .def_readwrite("lifespan_scale", &FlameParams::lifespanScale, "A (s), in [1/24, 2]: life A*i^3")
      .def_readwrite("breakaway_frequency", &FlameParams::breakawayFrequency,
                     "f (Hz); 0 = automatic 0.50 (|g|/2r)^0.5")
      .def_readwrite("separated_can_split", &FlameParams::separatedCanSplit)
      .def_readwrite("buoyancy", &FlameParams::buoyancy, "beta of eq. 2")
      .def_readwrite("ambient_temperature", &FlameParams::ambientTemperature, "T_0 of eq. 2")
      .def_readwrite("diffusion", &FlameParams::diffusion, "Brownian diffusion D (m^2/s), scaled by T_p")
      .def_property(
          "gravity", [](const FlameParams& p) { return vec3Tuple(p.gravity); },
          [](FlameParams& p, const py::object& g) { p.gravity = dvec3Arg(g, "gravity"); })
      .def_readwrite("integrator", &FlameParams::integrator)
      .def_readwrite("obstacle_margin", &FlameParams::obstacleMargin, "m kept outside obstacles")
      .def_property(
          "spine_noise_amplitude", [](const FlameParams& p) { return p.spineNoise.amplitude; },
          [](FlameParams& p, double v) { p.spineNoise.amplitude = v; },
          "RMS speed (m/s) of the Kolmogorov velocity v_K on the control points (eq. 1, §4.2); 0 = off")
      .def_property(
          "spine_noise_scale", [](const FlameParams& p) { return p.spineNoise.scale; },
          [](FlameParams& p, double v) { p.spineNoise.scale = v; }, "Lambda (m): the largest eddy of v_K")
      .def_property(
          "spine_noise_frequency", [](const FlameParams& p) { return p.spineNoise.frequency; },
          [](FlameParams& p, double v) { p.spineNoise.frequency = v; }, "nu (Hz): how fast v_K changes in place")
      .def_property(
          "spine_noise_drift", [](const FlameParams& p) { return vec3Tuple(p.spineNoise.drift); },
          [](FlameParams& p, const py::object& v) { p.spineNoise.drift = dvec3Arg(v, "spine_noise_drift"); },
          "c (m/s): the velocity carrying v_K's frozen turbulence")
      .def("validate", &FlameParams::validate, "Raises ValueError naming a bad setting and its range.")
      .def("frequency", &FlameParams::frequency, py::arg("radius"), "f (Hz) for a source of radius r (m)");

  py::class_<FlameSource>(m, "FlameSource",
                          "A burning surface point: position, normal, radius, motion V, active interval "
                          "[start_time, end_time) and spread-map scales (§4.2, §6.2).")
      .def(py::init<>())
      .def_property(
          "position", [](const FlameSource& s) { return vec3Tuple(s.position); },
          [](FlameSource& s, const py::object& v) { s.position = dvec3Arg(v, "position"); })
      .def_property(
          "normal", [](const FlameSource& s) { return vec3Tuple(s.normal); },
          [](FlameSource& s, const py::object& v) { s.normal = dvec3Arg(v, "normal"); })
      .def_property(
          "velocity", [](const FlameSource& s) { return vec3Tuple(s.velocity); },
          [](FlameSource& s, const py::object& v) { s.velocity = dvec3Arg(v, "velocity"); })
      .def_readwrite("radius", &FlameSource::radius)
      .def_readwrite("start_time", &FlameSource::startTime)
      .def_readwrite("end_time", &FlameSource::endTime)
      .def_readwrite("intensity", &FlameSource::intensity)
      .def_readwrite("diameter_scale", &FlameSource::diameterScale)
      .def_readwrite("height_scale", &FlameSource::heightScale)
      .def_readwrite("temperature", &FlameSource::temperature)
      .def_readwrite("brightness", &FlameSource::brightness,
                     "2^(Intensity in stops): scales eq. 5's E of its flames (emission and light), not their opacity");
}

void bindFields(py::module_& m) {
  py::class_<WindField, std::shared_ptr<WindField>>(m, "WindField", "w(x, t) of eq. 1 (m/s).")
      .def(
          "evaluate",
          [](const WindField& w, const py::object& x, double t) {
            std::vector<glm::dvec3> p = dpointsArg(x, "points");
            for (glm::dvec3& v : p) v = w.evaluate(v, t);
            return rowsArray(p);
          },
          py::arg("points"), py::arg("time") = 0.0, "Wind at (N, 3) points, as (N, 3).");
  py::class_<UniformWind, WindField, std::shared_ptr<UniformWind>>(
      m, "UniformWind", "Constant wind (Blender Wind: direction * strength).")
      .def(py::init([](const py::object& v) { return std::make_shared<UniformWind>(dvec3Arg(v, "velocity")); }),
           py::arg("velocity"));
  py::class_<VortexWind, WindField, std::shared_ptr<VortexWind>>(m, "VortexWind",
                                                                 "Rotation about an axis (Blender Vortex).")
      .def(py::init([](const py::object& c, const py::object& a, double s, double r) {
             return std::make_shared<VortexWind>(dvec3Arg(c, "center"), dvec3Arg(a, "axis"), s, r);
           }),
           py::arg("center"), py::arg("axis"), py::arg("strength"), py::arg("core_radius") = 0.1);
  py::class_<TurbulenceWind, WindField, std::shared_ptr<TurbulenceWind>>(
      m, "TurbulenceWind", "Divergence-free noise of rms speed `strength` (Blender Turbulence).")
      .def(py::init<double, double, double, std::uint64_t, int>(), py::arg("strength"), py::arg("size"),
           py::arg("flow") = 1.0, py::arg("seed") = 0, py::arg("modes") = 16);
  py::class_<GridWind, WindField, std::shared_ptr<GridWind>>(
      m, "GridWind", "Cell-centred velocity grid (nx, ny, nz, 3), read trilinearly (a solver cache).")
      .def(py::init([](const py::object& values, double cellSize, const py::object& origin) {
             const FloatArrayF a = FloatArrayF::ensure(values);
             if (!a || a.ndim() != 4 || a.shape(3) != 3)
               throw py::value_error("values must be an array of shape (nx, ny, nz, 3)");
             return std::make_shared<GridWind>(vectorGridOf(a), cellSize, dvec3Arg(origin, "origin"));
           }),
           py::arg("values"), py::arg("cell_size"), py::arg("origin"));
  py::class_<MacWind, WindField, std::shared_ptr<MacWind>>(
      m, "MacWind", "Staggered solver velocity: u (nx+1, ny, nz), v (nx, ny+1, nz), w (nx, ny, nz+1).")
      .def(py::init([](const py::object& u, const py::object& v, const py::object& w, double cellSize,
                       const py::object& origin) {
             ScalarGrid c[3] = {scalarGridArg(u, "u"), scalarGridArg(v, "v"), scalarGridArg(w, "w")};
             const glm::ivec3 cells = c[0].size() - glm::ivec3(1, 0, 0);
             if (c[1].size() != cells + glm::ivec3(0, 1, 0) || c[2].size() != cells + glm::ivec3(0, 0, 1))
               throw py::value_error("u, v, w must have shapes (nx+1, ny, nz), (nx, ny+1, nz), (nx, ny, nz+1)");
             MacGrid3 mac(cells);
             for (int a = 0; a < 3; ++a) mac.component(a) = std::move(c[a]);
             return std::make_shared<MacWind>(std::move(mac), cellSize, dvec3Arg(origin, "origin"));
           }),
           py::arg("u"), py::arg("v"), py::arg("w"), py::arg("cell_size"), py::arg("origin"));

  py::class_<ObstacleSdf, std::shared_ptr<ObstacleSdf>>(m, "ObstacleSdf",
                                                        "Signed distance of an obstacle (< 0 inside, m).")
      .def(
          "distance",
          [](const ObstacleSdf& o, const py::object& x) {
            const std::vector<glm::dvec3> p = dpointsArg(x, "points");
            py::array_t<double> d(py::ssize_t(p.size()));
            for (std::size_t i = 0; i < p.size(); ++i) d.mutable_data()[i] = o.distance(p[i]);
            return d;
          },
          py::arg("points"));
  py::class_<SphereSdf, ObstacleSdf, std::shared_ptr<SphereSdf>>(m, "SphereSdf")
      .def(py::init([](const py::object& c, double r) { return std::make_shared<SphereSdf>(dvec3Arg(c, "center"), r); }),
           py::arg("center"), py::arg("radius"));
  py::class_<BoxSdf, ObstacleSdf, std::shared_ptr<BoxSdf>>(m, "BoxSdf")
      .def(py::init([](const py::object& lo, const py::object& hi) {
             return std::make_shared<BoxSdf>(dvec3Arg(lo, "lower"), dvec3Arg(hi, "upper"));
           }),
           py::arg("lower"), py::arg("upper"));
  py::class_<GridSdf, ObstacleSdf, std::shared_ptr<GridSdf>>(
      m, "GridSdf", "Voxelized obstacle: cell-centred signed distances (nx, ny, nz), read trilinearly.")
      .def(py::init([](const py::object& v, double cellSize, const py::object& origin) {
             return std::make_shared<GridSdf>(scalarGridArg(v, "values"), cellSize, dvec3Arg(origin, "origin"));
           }),
           py::arg("values"), py::arg("cell_size"), py::arg("origin"));
}

void bindSystem(py::module_& m) {
  py::class_<FlameSystem>(m, "FlameSystem",
                          "Flames from sources: evolution (eq. 1-2), spine fitting and re-sampling, "
                          "breakaway (§4.3), obstacles (§6.1). Same params + seed: same flames.")
      .def(py::init<const FlameParams&, std::uint64_t>(), py::arg("params"), py::arg("seed") = 0)
      .def("add_source", &FlameSystem::addSource, py::arg("source"), "Adds a source; returns its index.")
      .def("set_source", &FlameSystem::setSource, py::arg("index"), py::arg("source"))
      .def_property_readonly("sources", &FlameSystem::sources)
      .def_property("params", &FlameSystem::params, &FlameSystem::setParams)
      .def(
          "add_wind", [](FlameSystem& s, std::shared_ptr<WindField> w) { s.wind().add(std::move(w)); },
          py::arg("field"))
      .def("clear_wind", [](FlameSystem& s) { s.wind().clear(); })
      .def(
          "add_obstacle", [](FlameSystem& s, std::shared_ptr<ObstacleSdf> o) { s.obstacles().add(std::move(o)); },
          py::arg("obstacle"))
      .def("clear_obstacles", [](FlameSystem& s) { s.obstacles().clear(); })
      .def("step", &FlameSystem::step, py::arg("dt"), py::call_guard<py::gil_scoped_release>(),
           "Advances the flames by dt seconds.")
      .def_property_readonly("time", &FlameSystem::time)
      .def(
          "spine_noise_velocity",
          [](const FlameSystem& s, const py::object& x, double t) {
            std::vector<glm::dvec3> p = dpointsArg(x, "points");
            for (glm::dvec3& v : p) v = s.spineNoise().velocity(v, t);
            return rowsArray(p);
          },
          py::arg("points"), py::arg("time") = 0.0, "v_K of eq. 1 (m/s) at (N, 3) points, as (N, 3).")
      .def(
          "flames",
          [](const FlameSystem& s) {
            py::list out;
            for (const Flame& f : s.flames()) out.append(flameDict(f));
            return out;
          },
          "Live flames as dicts: id, source, separated, age, lifespan, radius, intensity, temperature, "
          "points (n, 3), velocities (n, 3), ages (n,).")
      .def_property_readonly("statistics", [](const FlameSystem& s) {
        const FlameStatistics& st = s.statistics();
        py::dict d;
        d["eligible_time"] = st.eligibleTime;
        d["breakaways"] = st.breakaways;
        d["forced_breakaways"] = st.forcedBreakaways;
        d["separated_born"] = st.separatedBorn;
        d["separated_died"] = st.separatedDied;
        d["lifespan_sum"] = st.lifespanSum;
        d["age_at_death_sum"] = st.ageAtDeathSum;
        return d;
      });
}

void bindSpine(py::module_& m) {
  py::class_<Spine>(m, "Spine", "Interpolating cubic B-spline through points, chord-length parameters (§4.1).")
      .def(py::init([](const py::object& x) { return Spine(dpointsArg(x, "points")); }), py::arg("points"))
      .def_property_readonly("knots", &Spine::knots)
      .def_property_readonly("length", &Spine::length, "Arc length (m).")
      .def(
          "evaluate",
          [](const Spine& s, const std::vector<double>& u) {
            std::vector<glm::dvec3> p;
            for (double v : u) p.push_back(s.evaluate(v));
            return rowsArray(p);
          },
          py::arg("u"), "Points at parameters u, as (N, 3).")
      .def(
          "tangent",
          [](const Spine& s, const std::vector<double>& u) {
            std::vector<glm::dvec3> p;
            for (double v : u) p.push_back(s.tangent(v));
            return rowsArray(p);
          },
          py::arg("u"), "Unit tangents at parameters u, as (N, 3).")
      .def("arc_length", &Spine::arcLength, py::arg("u"))
      .def("parameter_at", &Spine::parameterAt, py::arg("s"));
  m.def(
      "spine_resample",
      [](const py::object& x, int count) {
        if (count < 2) throw py::value_error("count must be >= 2");
        std::vector<SpinePoint> pts;
        for (const glm::dvec3& p : dpointsArg(x, "points")) pts.push_back(SpinePoint{p, glm::dvec3(0.0), 0.0});
        if (pts.empty()) throw py::value_error("points must hold at least 1 point");
        std::vector<glm::dvec3> out;
        for (const SpinePoint& p : resampleSpine(pts, count)) out.push_back(p.x);
        return rowsArray(out);
      },
      py::arg("points"), py::arg("count"),
      "count points evenly spaced along the curve through points (N, 3); first and last kept (§4.1).");
}

}  // namespace

void bindFlamesStructure(py::module_& m) {
  bindSettings(m);
  bindFields(m);
  bindSystem(m);
  bindSpine(m);
}

}  // namespace plume::bindings
