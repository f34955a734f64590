/// \file bind_solver.cpp
/// SmokeSolver for Python (its settings are in bind_solver_params.cpp): NumPy conversions and
/// docstrings. Grids go out as copies shaped (nx, ny, nz) indexed [i, j, k]; the core stores x
/// fastest, which is NumPy's Fortran order, so a copy is one memcpy.

#include "bindings/bindings.h"
#include "bindings/convert.h"

#include "solver/state_file.h"
#include "io/vdb_frame.h"
#include "solver/emitters.h"
#include "solver/point_emitters.h"
#include "solver/smoke_solver.h"

#include <pybind11/stl.h>

#include <cmath>
#include <cstring>
#include <sstream>

namespace py = pybind11;

namespace plume::bindings {
namespace {

/// Copies an array of shape (nx, ny, nz) into a grid; ValueError on another shape or on NaN/inf
/// (the grid unchanged then).
void fromNumpy(const FloatArrayF& a, ScalarGrid& g, const char* name) {
  checkGridShape(a, g.size(), name);
  const float* p = a.data();
  for (std::size_t m = 0; m < g.count(); ++m)
    if (!std::isfinite(p[m])) throw py::value_error(std::string(name) + " contains NaN or inf");
  std::memcpy(g.data(), p, sizeof(float) * g.count());
}

// --- SmokeSolver -------------------------------------------------------------------------

using Getter = ScalarGrid& (SmokeSolver::*)();

void scalarAccess(py::class_<SmokeSolver>& c, const char* name, Getter getter, const char* doc) {
  const std::string n = name;
  c.def(("get_" + n).c_str(),
        [getter](SmokeSolver& s) { return gridArray((s.*getter)()); },
        (std::string("Copy of ") + doc + ", shape (nx, ny, nz), indexed [i, j, k].").c_str());
  c.def(("set_" + n).c_str(),
        [getter, n](SmokeSolver& s, const FloatArrayF& a) { fromNumpy(a, (s.*getter)(), n.c_str()); },
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
      [](SmokeSolver& s, const FloatArrayC& v, const Int64ArrayC& t,
         const DoubleArrayC& matrix, const DoubleArrayC& matrixNext,
         const SourceSettings& settings, const std::string& name) {
        settings.validate();
        EmitterMesh mesh = emitterMeshArg(v, t, matrix, matrixNext, name);
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
      [](SmokeSolver& s, const FloatArrayC& v, const Int64ArrayC& t,
         const DoubleArrayC& matrix, const DoubleArrayC& matrixNext, Slip slip,
         const std::string& name) {
        EmitterMesh mesh = emitterMeshArg(v, t, matrix, matrixNext, name);
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
          const FloatArrayF a = FloatArrayF::ensure(wind);
          if (!a) throw py::value_error("wind field must be a float array");
          const glm::ivec3 n = s.params().resolution;
          if (a.ndim() != 4 || a.shape(0) != n.x || a.shape(1) != n.y || a.shape(2) != n.z ||
              a.shape(3) != 3) {
            std::ostringstream e;
            e << "wind field must have shape (" << n.x << ", " << n.y << ", " << n.z
              << ", 3), got " << shapeText(a);
            throw py::value_error(e.str());
          }
          field = vectorGridOf(a);
        }
        s.setWindField(field);
      },
      py::arg("wind"),
      "Per-cell wind velocity u_wind, shape (nx, ny, nz, 3), replacing the constant `wind`; "
      "None restores the constant.");
  c.def(
      "set_point_emitters",
      [](SmokeSolver& s, const FloatArrayC& positions, const FloatArrayC& radii, const FloatArrayC& rates,
         const FloatArrayC& velocities, const FloatArrayC& temperatures) {
        const py::ssize_t count = positions.ndim() == 2 ? positions.shape(0) : 0;
        const auto rows = [count](const FloatArrayC& a, const char* name) {
          if (a.ndim() != 2 || a.shape(0) != count || a.shape(1) != 3)
            throw py::value_error(std::string(name) + " must have shape (N, 3) with N = " +
                                  std::to_string(count) + ", got " + shapeText(a));
        };
        const auto column = [count](const FloatArrayC& a, const char* name) {
          if (a.ndim() != 1 || a.shape(0) != count)
            throw py::value_error(std::string(name) + " must have shape (N,) with N = " +
                                  std::to_string(count) + ", got " + shapeText(a));
        };
        rows(positions, "positions");
        column(radii, "radii");
        column(rates, "density_rates");
        rows(velocities, "velocities");
        column(temperatures, "temperatures");
        s.setPointEmitters(pointEmittersFrom(std::size_t(count), positions.data(), radii.data(),
                                             rates.data(), velocities.data(), temperatures.data()));
      },
      py::arg("positions"), py::arg("radii"), py::arg("density_rates"), py::arg("velocities"),
      py::arg("temperatures"),
      "Replaces the point emitters ([Structural Flames] §6.3 smoke): centres (N, 3) m, sphere "
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
        return macArrays(s.velocity());
      },
      "Copies of the face velocities (u (nx+1, ny, nz), v (nx, ny+1, nz), w (nx, ny, nz+1)).");
  c.def(
      "set_velocity",
      [](SmokeSolver& s, const FloatArrayF& u, const FloatArrayF& v, const FloatArrayF& w) {
        // Check all three before writing any, so a bad w leaves u and v unchanged.
        MacGrid3 tmp(s.params().resolution);
        fromNumpy(u, tmp.u(), "u");
        fromNumpy(v, tmp.v(), "v");
        fromNumpy(w, tmp.w(), "w");
        s.velocity() = std::move(tmp);
      },
      py::arg("u"), py::arg("v"), py::arg("w"),
      "Sets the face velocities; shapes (nx+1, ny, nz), (nx, ny+1, nz), (nx, ny, nz+1).");
  c.def("get_cell_types", [](const SmokeSolver& s) { return gridArray(s.cellTypes()); },
        "uint8 (nx, ny, nz): 0 = fluid, 1 = solid.");

  c.def(
      "write_vdb",
      [](const SmokeSolver& s, const py::object& path, bool velocityEverywhere) {
        withPath(path, [&](const std::string& p) { writeVdbFrame(p, s, velocityEverywhere); });
      },
      py::arg("path"), py::arg("velocity_everywhere") = false,
      "Writes grids density (ρ + soot), temperature, flame (combustion only) and velocity "
      "(cell-centred; where there is smoke or flame, or in every cell with "
      "velocity_everywhere) to a VDB, atomically. RuntimeError on failure.");
  c.def(
      "save_state",
      [](const SmokeSolver& s, const py::object& path) {
        withPath(path, [&](const std::string& p) { writeState(p, s); });
      },
      py::arg("path"), "Writes a checkpoint (every grid and the frame), atomically.");
  c.def(
      "load_state",
      [](SmokeSolver& s, const py::object& path) {
        withPath(path, [&](const std::string& p) { readState(p, s); });
      },
      py::arg("path"),
      "Reads a checkpoint; RuntimeError on a missing, truncated, corrupt or mismatched file, "
      "leaving the solver unchanged.");
}

}  // namespace

void bindSolver(py::module_& m) {
  bindSolverParams(m);
  bindSmokeSolver(m);
}

}  // namespace plume::bindings
