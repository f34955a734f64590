/// \file bind_streak.cpp
/// Streaklines for Python ([Smoke Surfaces] §3.2): point sources, the tracer and the
/// per-frame streak files (their clustering, §3.3, is in bind_streak_clusters.cpp).
/// Conversions and docstrings only; long calls release the GIL.

#include "bindings/bindings.h"
#include "bindings/convert.h"

#include "tracers/streak_file.h"
#include "tracers/tracer_state_file.h"
#include "solver/emitters.h"
#include "solver/smoke_solver.h"
#include "tracers/point_sources.h"
#include "tracers/streak_tracer.h"
#include "tracers/tracer_driver.h"

#include <pybind11/stl.h>

namespace py = pybind11;

namespace plume::bindings {
namespace {

void bindTracer(py::module_& m) {
  py::class_<StreakTracer> c(
      m, "StreakTracer",
      "Streaklines (smoke_surfaces §3.2): particles emitted from point sources every emission "
      "period and advected by the solver's velocity with the midpoint rule (second order in "
      "time). After S steps each source holds floor(S / emission_period) + 1 particles, the "
      "youngest at the source, unless emission was paused (emitting = False, Figure 10). "
      "Particles carried through an open side go on with the velocity they left with "
      "(outside=True), so every streakline keeps the same count.");
  c.def(py::init([](const SmokeParams& p, int emissionPeriod, const py::object& interpolation) {
          StreakParams s;
          s.emissionPeriod = emissionPeriod;
          s.interpolation =
              interpolation.is_none() ? p.interpolation : interpolation.cast<Interpolation>();
          return std::make_unique<StreakTracer>(s, p);
        }),
        py::arg("params"), py::arg("emission_period") = 1, py::arg("interpolation") = py::none(),
        "Tracer on the domain and boundaries of SmokeParams `params`; interpolation defaults to "
        "params.interpolation. ValueError on emission_period outside [1, 100000].");
  c.def(
      "add_point_sources",
      [](StreakTracer& t, const FloatArrayC& positions, const Int64ArrayC& groups, const py::object& velocities) {
        const std::vector<glm::vec3> p = pointsArg(positions, "positions");
        std::vector<int> g = intsArg(groups, "groups");
        std::vector<glm::vec3> v;
        if (!velocities.is_none())
          v = pointsArg(ensureArray<FloatArrayC>(velocities, "velocities"), "velocities");
        return t.addPointSources(p, g, v);
      },
      py::arg("positions"), py::arg("groups"), py::arg("velocities") = py::none(),
      "Adds point sources: positions (N, 3) world, groups (N,) candidate group of each, "
      "velocities (N, 3) or None (still). Source IDs follow the order added; returns the first "
      "new ID. Only before the first step; ValueError on bad sizes or positions outside the "
      "domain. Emits each source's first particle.");
  c.def(
      "step",
      [](StreakTracer& t, const py::object& before, const py::object& after, const FloatArrayF& density,
         float dt) {
        const glm::ivec3 n = t.gridFrame().resolution;
        MacGrid3 b, a;
        ScalarGrid d;
        copyMac(before, n, b, "before");
        copyMac(after, n, a, "after");
        copyGrid(density, n, d, "density");
        py::gil_scoped_release release;
        t.step(b, a, d, dt);
      },
      py::arg("before"), py::arg("after"), py::arg("density"), py::arg("dt"),
      "One step of length dt from the face velocities (u, v, w) at its start and end (shapes as "
      "SmokeSolver.get_velocity()) and the density (nx, ny, nz) at its end.");
  c.def("snapshot", [](const StreakTracer& t) { return streakFrameDict(t.snapshot()); },
        "The streaklines now: dict(counts (S,) int32, positions (M, 3) float32, density (M,) "
        "float32, groups (S,) int32, outside (M,) bool); source s owns counts[s] particles from "
        "sum(counts[:s]), oldest first.");
  c.def_property(
      "emitting", &StreakTracer::emitting, &StreakTracer::setEmitting,
      "False pauses emission (smoke_surfaces §3.2, Figure 10: \"particle emission was turned "
      "off\"): the emission instants reached while paused add no particles, so the streaklines "
      "show a gap; particles already emitted keep moving. Per tracer, so every streakline keeps "
      "the same count. Saved in checkpoints. Default True.");
  c.def("cancel", &StreakTracer::cancel,
        "Thread-safe: a running advance_frame_with_tracers() returns False before its next step.");
  c.def(
      "save_state",
      [](const StreakTracer& t, const py::object& path, int frame) {
        withPath(path, [&](const std::string& p) { writeTracerState(p, t, frame); });
      },
      py::arg("path"), py::arg("frame"),
      "Writes a checkpoint (point sources, particles, density, outside flags, exit velocities, "
      "emission count, steps, the emitting switch and settings) labelled with `frame`, atomically. RuntimeError "
      "naming the path if it cannot be written.");
  c.def(
      "load_state",
      [](StreakTracer& t, const py::object& path) {
        return withPath(path, [&](const std::string& p) { return readTracerState(p, t); });
      },
      py::arg("path"),
      "Reads a checkpoint written by save_state() and returns its frame label. RuntimeError on a "
      "missing, truncated, corrupt or mismatched file (other emission period, interpolation, "
      "domain or boundaries), leaving the tracer unchanged.");
  c.def_property_readonly("source_count", &StreakTracer::sourceCount, "Number of point sources.");
  c.def_property_readonly("particles_per_source", &StreakTracer::particlesPerSource,
                          "floor(steps / emission_period) + 1 less the emission instants "
                          "skipped while paused.");
  c.def_property_readonly("steps", &StreakTracer::steps, "Steps seen so far.");
  c.def_property_readonly("emission_period",
                          [](const StreakTracer& t) { return t.params().emissionPeriod; },
                          "Steps between two emissions.");
  c.def_property_readonly("interpolation",
                          [](const StreakTracer& t) { return t.params().interpolation; },
                          "Interpolation of velocity and density.");
}

}  // namespace

void bindStreak(py::module_& m) {
  m.def(
      "random_points_in_cells",
      [](const Int64ArrayC& cells, const py::object& resolution, float cellSize, const py::object& origin,
         int pointsPerCell, std::uint64_t seed, std::uint64_t stream) {
        CellSet set;
        for (int c : intsArg(cells, "cells")) {
          if (c < 0) throw py::value_error("cells must hold linear indices >= 0");
          set.cells.push_back(std::uint32_t(c));
        }
        const glm::ivec3 res = ivec3Arg(resolution, "resolution", 1, 1 << 20, "in [1, 1048576] per axis");
        return rowsArray(
            randomPointsInCells(set, res, cellSize, vec3Arg(origin, "origin", Vec3Form::Sequence), pointsPerCell, seed, stream));
      },
      py::arg("cells"), py::arg("resolution"), py::arg("cell_size"), py::arg("origin"),
      py::arg("points_per_cell"), py::arg("seed"), py::arg("stream") = 0,
      "smoke_surfaces §3.2: points_per_cell random world positions uniform in each cell (linear "
      "indices i + nx*(j + ny*k)); point n lies in cells[n // points_per_cell]. float32 (N, 3), "
      "deterministic for (seed, stream).");
  m.def(
      "source_cells",
      [](const FloatArrayC& v, const Int64ArrayC& t, const DoubleArrayC& matrix, const DoubleArrayC& matrixNext,
         const SmokeParams& p, const std::string& name) {
        pointsArg(v, "vertices");  // names the argument alone, as source_cells always has
        const EmitterMesh mesh = emitterMeshArg(v, t, matrix, matrixNext, name);
        const GridFrame grid{p.resolution, p.cellSize, p.origin, p.frameDt};
        CellSet cells;
        {
          py::gil_scoped_release release;
          cells = voxelizeSource(mesh, grid);
        }
        std::vector<glm::vec3> vel = cells.velocity;
        if (vel.empty()) vel.assign(cells.cells.size(), glm::vec3(0.f));
        return py::make_tuple(array1D(cells.cells), rowsArray(vel));
      },
      py::arg("vertices"), py::arg("triangles"), py::arg("matrix"), py::arg("matrix_next"),
      py::arg("params"), py::arg("name") = "",
      "The cells SmokeSolver.add_source() would fill for this mesh, as (cells (n,) uint32 linear "
      "indices, velocity (n, 3) float32 of the object's own motion); for placing point sources.");

  bindTracer(m);

  m.def(
      "advance_frame_with_tracers",
      [](SmokeSolver& solver, StreakTracer& tracer) {
        py::gil_scoped_release release;
        return advanceFrameWithTracers(solver, tracer);
      },
      py::arg("solver"), py::arg("tracer"),
      "solver.advance_frame() with the tracer following every substep (smoke_surfaces §3.2). "
      "Releases the GIL. Returns False when solver.cancel() or tracer.cancel() was called; "
      "discard both then.");

  m.def(
      "write_streak_file",
      [](const py::object& path, const py::dict& snapshot) {
        const StreakFrame f = streakFrameArg(snapshot, true, "snapshot");
        withPath(path, [&](const std::string& p) { writeStreakFile(p, f); });
      },
      py::arg("path"), py::arg("snapshot"),
      "Writes a snapshot dict (counts, positions, density; groups and outside optional) as a "
      "streak file, atomically. ValueError on inconsistent sizes, RuntimeError naming the path "
      "if it cannot be written.");
  m.def(
      "read_streak_file",
      [](const py::object& path) { return streakFrameDict(withPath(path, readStreakFile)); },
      py::arg("path"),
      "Reads a streak file into a snapshot dict. RuntimeError naming the path if it is missing, "
      "truncated or corrupt.");
  m.def("streak_file_name", &streakFileName, py::arg("frame"), "'streaks_0007.bin' for frame 7.");
}

}  // namespace plume::bindings
