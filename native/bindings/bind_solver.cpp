/// \file bind_solver.cpp
/// SmokeParams, SourceSettings and SmokeSolver for Python: NumPy conversions and docstrings.
/// Grids go out as copies shaped (nx, ny, nz) indexed [i, j, k]; the core stores x fastest,
/// which is NumPy's Fortran order, so a copy is one memcpy.

#include "bindings/bindings.h"

#include "io/state_file.h"
#include "io/vdb_frame.h"
#include "solver/emitters.h"
#include "solver/smoke_solver.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

namespace py = pybind11;

namespace plume::bindings {
namespace {

using FArray = py::array_t<float, py::array::f_style | py::array::forcecast>;
using CArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

// --- small conversions -------------------------------------------------------------------

glm::vec3 toVec3(const py::object& o, const char* name) {
  if (!py::isinstance<py::sequence>(o) || py::len(o) != 3)
    throw py::value_error(std::string(name) + " must be a sequence of 3 numbers");
  py::sequence s = py::reinterpret_borrow<py::sequence>(o);
  return {s[0].cast<float>(), s[1].cast<float>(), s[2].cast<float>()};
}

py::tuple fromVec3(glm::vec3 v) { return py::make_tuple(v.x, v.y, v.z); }

glm::ivec3 toIVec3(const py::object& o, const char* name) {
  if (!py::isinstance<py::sequence>(o) || py::len(o) != 3)
    throw py::value_error(std::string(name) + " must be a sequence of 3 integers");
  py::sequence s = py::reinterpret_borrow<py::sequence>(o);
  glm::ivec3 r;
  for (int a = 0; a < 3; ++a) {
    const long long v = s[a].cast<long long>();
    if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
      throw py::value_error(std::string(name) + " must be in [2, 1024] cells per axis");
    r[a] = int(v);
  }
  return r;
}

std::string shapeText(const py::array& a) {
  std::ostringstream s;
  s << "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) s << (d ? ", " : "") << a.shape(d);
  s << (a.ndim() == 1 ? ",)" : ")");
  return s.str();
}

/// A copy of a grid as an (nx, ny, nz) Fortran-ordered array.
template <typename T>
py::array_t<T> toNumpy(const Grid3<T>& g) {
  const glm::ivec3 n = g.size();
  py::array_t<T, py::array::f_style> a({py::ssize_t(n.x), py::ssize_t(n.y), py::ssize_t(n.z)});
  std::memcpy(a.mutable_data(), g.data(), sizeof(T) * g.count());
  return a;
}

/// Copies an array of shape (nx, ny, nz) into a grid; ValueError on another shape or on NaN/inf.
void fromNumpy(const FArray& a, ScalarGrid& g, const char* name) {
  const glm::ivec3 n = g.size();
  if (a.ndim() != 3 || a.shape(0) != n.x || a.shape(1) != n.y || a.shape(2) != n.z) {
    std::ostringstream s;
    s << name << " must have shape (" << n.x << ", " << n.y << ", " << n.z << "), got "
      << shapeText(a);
    throw py::value_error(s.str());
  }
  const float* p = a.data();
  for (std::size_t m = 0; m < g.count(); ++m)
    if (!std::isfinite(p[m])) throw py::value_error(std::string(name) + " contains NaN or inf");
  std::memcpy(g.data(), p, sizeof(float) * g.count());
}

glm::mat4 toMatrix(const py::array_t<double, py::array::forcecast>& a, const char* name) {
  if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
    throw py::value_error(std::string(name) + " must be a 4x4 matrix, got shape " + shapeText(a));
  auto r = a.unchecked<2>();
  glm::mat4 m;
  // numpy.array(obj.matrix_world) is row-major (world = M @ [x, y, z, 1]); glm is column-major.
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) m[col][row] = float(r(row, col));
  return m;
}

EmitterMesh toMesh(const py::array_t<float, py::array::c_style | py::array::forcecast>& vertices,
                   const py::array_t<long long, py::array::c_style | py::array::forcecast>& triangles,
                   const py::array_t<double, py::array::forcecast>& matrix,
                   const py::array_t<double, py::array::forcecast>& matrixNext,
                   const std::string& name) {
  EmitterMesh mesh;
  mesh.name = name;
  const bool emptyV = vertices.size() == 0, emptyT = triangles.size() == 0;
  if (!emptyV && (vertices.ndim() != 2 || vertices.shape(1) != 3))
    throw py::value_error("vertices of '" + name + "' must have shape (N, 3), got " +
                          shapeText(vertices));
  if (!emptyT && (triangles.ndim() != 2 || triangles.shape(1) != 3))
    throw py::value_error("triangles of '" + name + "' must have shape (M, 3), got " +
                          shapeText(triangles));
  const std::size_t nv = emptyV ? 0 : std::size_t(vertices.shape(0));
  const std::size_t nt = emptyT ? 0 : std::size_t(triangles.shape(0));
  mesh.vertices.resize(nv);
  std::memcpy(mesh.vertices.data(), vertices.data(), nv * 3 * sizeof(float));
  mesh.triangles.resize(nt);
  const long long* t = triangles.data();
  for (std::size_t n = 0; n < nt * 3; ++n) {
    if (t[n] < 0 || t[n] >= (long long)nv) {
      std::ostringstream s;
      s << "triangles of '" << name << "' index vertex " << t[n] << ", outside [0, " << nv << ")";
      throw py::value_error(s.str());
    }
    mesh.triangles[n / 3][int(n % 3)] = int(t[n]);
  }
  mesh.matrix = toMatrix(matrix, "matrix");
  mesh.matrixNext = toMatrix(matrixNext, "matrix_next");
  return mesh;
}

// --- SmokeParams -------------------------------------------------------------------------

/// Adds a read/write property for a plain field.
template <typename T>
void field(py::class_<SmokeParams>& c, const char* name, T SmokeParams::*member, const char* doc) {
  c.def_readwrite(name, member, doc);
}

void bindParams(py::module_& m) {
  py::enum_<Trace>(m, "Trace",
                   "Back-trace of semi-Lagrangian advection: MIDPOINT (explicit midpoint rule, "
                   "second order) or EULER (one step with the velocity at the sample, first "
                   "order, no interpolation: Mantaflow's default).")
      .value("MIDPOINT", Trace::Midpoint)
      .value("EULER", Trace::Euler);
  py::class_<SmokeParams> c(m, "SmokeParams",
                            "Every setting of the smoke/fire solver (Stam 1999; Fedkiw 2001; "
                            "graph_fire_synthesis eqs. 1-5). Units: metres, seconds.");
  c.def(py::init<>());
  c.def(py::init([](const py::kwargs& kwargs) {
          py::object self = py::cast(SmokeParams());
          for (auto item : kwargs) {
            const std::string key = py::str(item.first);
            if (!py::hasattr(self, item.first) || key.rfind("_", 0) == 0 || key == "validate" ||
                key == "size")
              throw py::type_error("SmokeParams has no setting '" + key + "'");
            py::setattr(self, item.first, item.second);
          }
          return self.cast<SmokeParams>();
        }),
        "SmokeParams(**settings): defaults, then the given settings by name.");
  c.def(py::init<const SmokeParams&>(), "A copy.");
  c.def("__copy__", [](const SmokeParams& p) { return SmokeParams(p); });
  c.def("__deepcopy__", [](const SmokeParams& p, py::dict) { return SmokeParams(p); });

  c.def_property(
      "resolution",
      [](const SmokeParams& p) { return py::make_tuple(p.resolution.x, p.resolution.y, p.resolution.z); },
      [](SmokeParams& p, const py::object& v) { p.resolution = toIVec3(v, "resolution"); },
      "Cells per axis (nx, ny, nz).");
  c.def_readwrite("cell_size", &SmokeParams::cellSize, "Δx, metres.");
  c.def_property(
      "origin", [](const SmokeParams& p) { return fromVec3(p.origin); },
      [](SmokeParams& p, const py::object& v) { p.origin = toVec3(v, "origin"); },
      "World position of the domain's minimum corner.");
  c.def_property(
      "boundaries",
      [](const SmokeParams& p) { return std::vector<Boundary>(p.boundaries.begin(), p.boundaries.end()); },
      [](SmokeParams& p, const std::vector<Boundary>& b) {
        if (b.size() != 6)
          throw py::value_error("boundaries must list 6 sides (-x, +x, -y, +y, -z, +z)");
        std::copy(b.begin(), b.end(), p.boundaries.begin());
      },
      "Sides -x, +x, -y, +y, -z, +z: Boundary.OPEN (p = 0) or Boundary.CLOSED (wall).");
  field(c, "frame_dt", &SmokeParams::frameDt, "Seconds per frame (1/fps × time scale).");
  field(c, "substeps", &SmokeParams::substeps, "Minimum steps per frame.");
  field(c, "use_cfl", &SmokeParams::useCfl, "Add steps so no cell moves more than `cfl` cells.");
  field(c, "cfl", &SmokeParams::cfl, "CFL number of the adaptive steps.");
  field(c, "advection", &SmokeParams::advection,
        "Advection.SEMI_LAGRANGIAN, Advection.BFECC or Advection.MACCORMACK.");
  field(c, "interpolation", &SmokeParams::interpolation,
        "Interpolation.LINEAR or Interpolation.MONOTONIC_CUBIC (Fedkiw 2001 eq. 12-13).");
  field(c, "trace", &SmokeParams::trace,
        "Trace.MIDPOINT (RK2, the default) or Trace.EULER (first order, grid-point velocity).");
  field(c, "conserve_mass", &SmokeParams::conserveMass,
        "Restore the total smoke (and heat, T - T_amb) after each advection, less what left "
        "through open sides.");
  c.def_property(
      "gravity", [](const SmokeParams& p) { return fromVec3(p.gravity); },
      [](SmokeParams& p, const py::object& v) { p.gravity = toVec3(v, "gravity"); },
      "g, m/s²; buoyancy acts against it.");
  field(c, "alpha", &SmokeParams::alpha, "α: buoyancy from density (Fedkiw 2001 eq. 8).");
  field(c, "beta", &SmokeParams::beta, "β: buoyancy from heat, f = -g (α ρ + β (T - T_amb)).");
  field(c, "ambient_temperature", &SmokeParams::ambientTemperature, "T_amb (T_0 of the fire paper).");
  c.def_property(
      "wind", [](const SmokeParams& p) { return fromVec3(p.wind); },
      [](SmokeParams& p, const py::object& v) { p.wind = toVec3(v, "wind"); },
      "Wind velocity u_wind the air is pulled towards, m/s.");
  field(c, "wind_strength", &SmokeParams::windStrength, "k_w: f_wind = k_w (u_wind - u), 1/s.");
  field(c, "vorticity", &SmokeParams::vorticity, "ε: vorticity confinement (Fedkiw 2001 eq. 11).");
  field(c, "density_dissipation", &SmokeParams::densityDissipation, "Fraction of ρ lost per second.");
  field(c, "pressure_tolerance", &SmokeParams::pressureTolerance, "MGPCG stop at |r|/|b| below this.");
  field(c, "max_pressure_iterations", &SmokeParams::maxPressureIterations, "MGPCG iteration cap.");
  field(c, "combustion", &SmokeParams::combustion, "Burn fuel (graph_fire_synthesis eqs. 1-5).");
  field(c, "burn_rate", &SmokeParams::burnRate, "r: dF/dt = -r F, 1/s.");
  field(c, "soot_yield", &SmokeParams::sootYield, "k_S: soot per unit fuel burnt.");
  field(c, "heat_yield", &SmokeParams::heatYield, "k_T: heat per unit fuel burnt.");
  field(c, "conductivity", &SmokeParams::conductivity, "κ: thermal conductivity, m²/s.");
  field(c, "cooling_rate", &SmokeParams::coolingRate, "c: cooling c ((T - T_0)/(T_max - T_0))^4 per s.");
  field(c, "max_temperature", &SmokeParams::maxTemperature, "T_max.");
  field(c, "expansion", &SmokeParams::expansion, "φ: divergence per unit fuel burnt per s (eq. 1).");
  field(c, "seed", &SmokeParams::seed, "Seed of every random choice.");
  field(c, "threads", &SmokeParams::threads, "Worker threads; 0 = all cores.");
  c.def("validate", &SmokeParams::validate,
        "Raises ValueError naming the first bad setting and its accepted range.");
  c.def("size", [](const SmokeParams& p) { return fromVec3(p.size()); },
        "World-space size of the domain (resolution × cell_size).");
  c.def("__repr__", [](const SmokeParams& p) {
    std::ostringstream s;
    s << "SmokeParams(resolution=(" << p.resolution.x << ", " << p.resolution.y << ", "
      << p.resolution.z << "), cell_size=" << p.cellSize << ", combustion="
      << (p.combustion ? "True" : "False") << ")";
    return s.str();
  });
}

void bindSourceSettings(py::module_& m) {
  py::class_<SourceSettings> c(m, "SourceSettings", "What a source puts into its cells each step.");
  c.def(py::init<>());
  c.def_readwrite("density", &SourceSettings::density,
                  "ρ set in source cells (the larger of this and what is there).");
  c.def_readwrite("temperature", &SourceSettings::temperature, "T - T_amb set in source cells.");
  c.def_readwrite("fuel", &SourceSettings::fuel, "F set in source cells (combustion).");
  c.def_property(
      "velocity", [](const SourceSettings& s) { return fromVec3(s.velocity); },
      [](SourceSettings& s, const py::object& v) { s.velocity = toVec3(v, "velocity"); },
      "Initial velocity, m/s (smoke_surfaces §3.2).");
  c.def_readwrite("motion_factor", &SourceSettings::motionFactor,
                  "Share of the source object's own motion added to its velocity.");
  c.def("validate", &SourceSettings::validate, "Raises ValueError naming a bad setting.");
}

// --- SmokeSolver -------------------------------------------------------------------------

using Getter = ScalarGrid& (SmokeSolver::*)();

void scalarAccess(py::class_<SmokeSolver>& c, const char* name, Getter getter, const char* doc) {
  const std::string n = name;
  c.def(("get_" + n).c_str(),
        [getter](SmokeSolver& s) { return toNumpy<float>((s.*getter)()); },
        (std::string("Copy of ") + doc + ", shape (nx, ny, nz), indexed [i, j, k].").c_str());
  c.def(("set_" + n).c_str(),
        [getter, n](SmokeSolver& s, const FArray& a) { fromNumpy(a, (s.*getter)(), n.c_str()); },
        py::arg("values"),
        (std::string("Sets ") + doc + " from an array of shape (nx, ny, nz) (ValueError otherwise).")
            .c_str());
}

void bindSmokeSolver(py::module_& m) {
  py::class_<SmokeSolver> c(m, "SmokeSolver",
                            "One smoke/fire simulation: fractional steps (Stam 1999) of sources, "
                            "forces, advection, combustion and projection.");
  c.def(py::init<const SmokeParams&>(), py::arg("params"),
        "Validates params (ValueError) and allocates the grids.");
  c.def_property_readonly("params", [](const SmokeSolver& s) { return s.params(); },
                          "A copy of the settings.");
  c.def("clear_emitters", &SmokeSolver::clearEmitters, "Removes all sources and obstacles.");
  c.def(
      "add_source",
      [](SmokeSolver& s, const py::array_t<float, py::array::c_style | py::array::forcecast>& v,
         const py::array_t<long long, py::array::c_style | py::array::forcecast>& t,
         const py::array_t<double, py::array::forcecast>& matrix,
         const py::array_t<double, py::array::forcecast>& matrixNext,
         const SourceSettings& settings, const std::string& name) {
        settings.validate();
        EmitterMesh mesh = toMesh(v, t, matrix, matrixNext, name);
        py::gil_scoped_release release;
        CellSet cells = voxelizeSource(mesh, s.gridFrame());
        const std::size_t count = cells.cells.size();
        s.addSource(cells, settings);
        return count;
      },
      py::arg("vertices"), py::arg("triangles"), py::arg("matrix"), py::arg("matrix_next"),
      py::arg("settings"), py::arg("name") = "",
      "Voxelizes a source mesh (vertices (N, 3) object-local, triangles (M, 3), 4x4 row-major "
      "matrices at frames f and f+1) and adds it; returns its cell count. Cells inside or within "
      "half a cell of the surface emit, so planes emit too.");
  c.def(
      "add_obstacle",
      [](SmokeSolver& s, const py::array_t<float, py::array::c_style | py::array::forcecast>& v,
         const py::array_t<long long, py::array::c_style | py::array::forcecast>& t,
         const py::array_t<double, py::array::forcecast>& matrix,
         const py::array_t<double, py::array::forcecast>& matrixNext, Slip slip,
         const std::string& name) {
        EmitterMesh mesh = toMesh(v, t, matrix, matrixNext, name);
        py::gil_scoped_release release;
        CellSet cells = voxelizeObstacle(mesh, s.gridFrame());
        const std::size_t count = cells.cells.size();
        s.addObstacle(cells, slip);
        return count;
      },
      py::arg("vertices"), py::arg("triangles"), py::arg("matrix"), py::arg("matrix_next"),
      py::arg("slip") = Slip::NoSlip, py::arg("name") = "",
      "Voxelizes a closed obstacle mesh (cells with φ < 0) and adds it with its motion velocity; "
      "returns its cell count. ValueError naming the object if the mesh is empty or not closed.");
  c.def(
      "set_wind_field",
      [](SmokeSolver& s, const py::object& wind) {
        VectorGrid field;
        if (!wind.is_none()) {
          auto a = py::array_t<float, py::array::f_style | py::array::forcecast>::ensure(wind);
          if (!a) throw py::value_error("wind field must be a float array");
          const glm::ivec3 n = s.params().resolution;
          if (a.ndim() != 4 || a.shape(0) != n.x || a.shape(1) != n.y || a.shape(2) != n.z ||
              a.shape(3) != 3) {
            std::ostringstream e;
            e << "wind field must have shape (" << n.x << ", " << n.y << ", " << n.z
              << ", 3), got " << shapeText(a);
            throw py::value_error(e.str());
          }
          field.resize(n);
          auto r = a.unchecked<4>();
          for (int k = 0; k < n.z; ++k)
            for (int j = 0; j < n.y; ++j)
              for (int i = 0; i < n.x; ++i) field(i, j, k) = {r(i, j, k, 0), r(i, j, k, 1), r(i, j, k, 2)};
        }
        s.setWindField(field);
      },
      py::arg("wind"),
      "Per-cell wind velocity u_wind, shape (nx, ny, nz, 3), replacing the constant `wind`; "
      "None restores the constant.");
  c.def(
      "set_point_emitters",
      [](SmokeSolver& s, const CArray& positions, const CArray& radii, const CArray& rates,
         const CArray& velocities, const CArray& temperatures) {
        const py::ssize_t count = positions.ndim() == 2 ? positions.shape(0) : 0;
        const auto rows = [count](const CArray& a, const char* name) {
          if (a.ndim() != 2 || a.shape(0) != count || a.shape(1) != 3)
            throw py::value_error(std::string(name) + " must have shape (N, 3) with N = " +
                                  std::to_string(count) + ", got " + shapeText(a));
        };
        const auto column = [count](const CArray& a, const char* name) {
          if (a.ndim() != 1 || a.shape(0) != count)
            throw py::value_error(std::string(name) + " must have shape (N,) with N = " +
                                  std::to_string(count) + ", got " + shapeText(a));
        };
        rows(positions, "positions");
        column(radii, "radii");
        column(rates, "density_rates");
        rows(velocities, "velocities");
        column(temperatures, "temperatures");
        std::vector<PointEmitter> emitters(static_cast<std::size_t>(count));
        for (py::ssize_t n = 0; n < count; ++n) {
          PointEmitter& e = emitters[std::size_t(n)];
          for (int a = 0; a < 3; ++a) {
            e.position[a] = positions.at(n, a);
            e.velocity[a] = velocities.at(n, a);
          }
          e.radius = radii.at(n);
          e.densityRate = rates.at(n);
          e.temperature = temperatures.at(n);
        }
        s.setPointEmitters(std::move(emitters));
      },
      py::arg("positions"), py::arg("radii"), py::arg("density_rates"), py::arg("velocities"),
      py::arg("temperatures"),
      "Replaces the point emitters (structural_flames.txt §6.3 smoke): centres (N, 3) m, sphere "
      "radii (N,) m (at least one cell is used), mass rates (N,) in density x m^3 per second, "
      "face velocities (N, 3) m/s, temperatures (N,) above ambient. Applied every step until "
      "replaced or clear_emitters(); ValueError on bad shapes or values.");

  c.def("advance_frame", [](SmokeSolver& s) { return s.advanceFrame(); }, py::call_guard<py::gil_scoped_release>(),
        "Advances one frame (substeps, more if the CFL condition needs them). Releases the GIL. "
        "Returns False when cancel() was called; the state is then mid-frame and must be "
        "discarded.");
  c.def("cancel", &SmokeSolver::cancel,
        "Thread-safe: a running advance_frame() returns False after its current step.");
  c.def("step", &SmokeSolver::step, py::arg("dt"), py::call_guard<py::gil_scoped_release>(),
        "One fractional step of dt seconds.");
  c.def("apply_sources", &SmokeSolver::applySources, py::arg("dt"),
        py::call_guard<py::gil_scoped_release>(), "Stage: source cells.");
  c.def("add_forces", &SmokeSolver::addForces, py::arg("dt"),
        py::call_guard<py::gil_scoped_release>(),
        "Stage: buoyancy (Fedkiw 2001 eq. 8), wind, vorticity confinement (eq. 11).");
  c.def("advect", &SmokeSolver::advect, py::arg("dt"), py::call_guard<py::gil_scoped_release>(),
        "Stage: semi-Lagrangian, BFECC or MacCormack advection of velocity and scalars.");
  c.def("burn", &SmokeSolver::burn, py::arg("dt"), py::call_guard<py::gil_scoped_release>(),
        "Stage: combustion (graph_fire_synthesis eqs. 3-5) and divergence φ (eq. 1).");
  c.def("dissipate", &SmokeSolver::dissipate, py::arg("dt"),
        py::call_guard<py::gil_scoped_release>(), "Stage: density loss ρ *= e^(-d dt).");
  c.def("project", &SmokeSolver::project, py::arg("dt"), py::call_guard<py::gil_scoped_release>(),
        "Stage: pressure projection to div u = φ (MGPCG).");

  c.def_property("frame", &SmokeSolver::frame, &SmokeSolver::setFrame, "Current frame number.");
  c.def_property_readonly(
      "last_stats",
      [](const SmokeSolver& s) {
        const StepStats& st = s.lastStats();
        py::dict d;
        d["substeps"] = st.substeps;
        d["pressure_iterations"] = st.pressureIterations;
        d["pressure_residual"] = st.pressureResidual;
        d["max_speed"] = st.maxSpeed;
        return d;
      },
      "Figures of the last frame: substeps, pressure_iterations, pressure_residual, max_speed.");
  c.def("max_divergence", &SmokeSolver::maxDivergence,
        "Largest |div u - φ| Δx over fluid cells divided by the largest |u|.");
  c.def("max_speed", &SmokeSolver::maxSpeed, "Largest face speed, m/s.");

  scalarAccess(c, "density", &SmokeSolver::density, "smoke density ρ");
  scalarAccess(c, "temperature", &SmokeSolver::temperature, "temperature T - T_amb");
  scalarAccess(c, "fuel", &SmokeSolver::fuel, "fuel F");
  scalarAccess(c, "soot", &SmokeSolver::soot, "soot S");
  scalarAccess(c, "flame", &SmokeSolver::flame, "flame (fuel burning per step)");
  scalarAccess(c, "pressure", &SmokeSolver::pressure, "pressure p");
  c.def(
      "get_velocity",
      [](const SmokeSolver& s) {
        const MacGrid3& v = s.velocity();
        return py::make_tuple(toNumpy<float>(v.u()), toNumpy<float>(v.v()), toNumpy<float>(v.w()));
      },
      "Copies of the face velocities (u (nx+1, ny, nz), v (nx, ny+1, nz), w (nx, ny, nz+1)).");
  c.def(
      "set_velocity",
      [](SmokeSolver& s, const FArray& u, const FArray& v, const FArray& w) {
        // Check all three before writing any, so a bad w leaves u and v unchanged.
        MacGrid3 tmp(s.params().resolution);
        fromNumpy(u, tmp.u(), "u");
        fromNumpy(v, tmp.v(), "v");
        fromNumpy(w, tmp.w(), "w");
        s.velocity() = std::move(tmp);
      },
      py::arg("u"), py::arg("v"), py::arg("w"),
      "Sets the face velocities; shapes (nx+1, ny, nz), (nx, ny+1, nz), (nx, ny, nz+1).");
  c.def("get_cell_types", [](const SmokeSolver& s) { return toNumpy<std::uint8_t>(s.cellTypes()); },
        "uint8 (nx, ny, nz): 0 = fluid, 1 = solid.");

  c.def(
      "write_vdb",
      [](const SmokeSolver& s, const py::object& path, bool velocityEverywhere) {
        const std::string p = pathArg(path);
        py::gil_scoped_release release;
        writeVdbFrame(p, s, velocityEverywhere);
      },
      py::arg("path"), py::arg("velocity_everywhere") = false,
      "Writes grids density (ρ + soot), temperature, flame (combustion only) and velocity "
      "(cell-centred; where there is smoke or flame, or in every cell with "
      "velocity_everywhere) to a VDB, atomically. RuntimeError on failure.");
  c.def(
      "save_state",
      [](const SmokeSolver& s, const py::object& path) {
        const std::string p = pathArg(path);
        py::gil_scoped_release release;
        writeState(p, s);
      },
      py::arg("path"), "Writes a checkpoint (every grid and the frame), atomically.");
  c.def(
      "load_state",
      [](SmokeSolver& s, const py::object& path) {
        const std::string p = pathArg(path);
        py::gil_scoped_release release;
        readState(p, s);
      },
      py::arg("path"),
      "Reads a checkpoint; RuntimeError on a missing, truncated, corrupt or mismatched file, "
      "leaving the solver unchanged.");
}

}  // namespace

void bindSolver(py::module_& m) {
  bindParams(m);
  bindSourceSettings(m);
  bindSmokeSolver(m);
}

}  // namespace plume::bindings
