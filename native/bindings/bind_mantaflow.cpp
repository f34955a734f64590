/// \file bind_mantaflow.cpp
/// Streaklines driven by a baked Blender Mantaflow cache ([Smoke Surfaces] §3.2):
/// the Mantaflow grid's placement, its VDB frames, the volume frames written from them and the
/// tracer that runs through them. Conversions and docstrings only; file reads, writes and
/// frames release the GIL.

#include "bindings/bindings.h"
#include "bindings/convert.h"

#include "io/mantaflow_cache.h"
#include "tracers/streak_file.h"
#include "tracers/mantaflow_driver.h"

#include <pybind11/stl.h>

namespace py = pybind11;

namespace plume::bindings {
namespace {

/// (N, 3) float array as points (an empty array: none); the message gives no shape.
std::vector<glm::vec3> pointsInput(const FloatArrayC& a, const char* name) {
  if (a.size() != 0 && (a.ndim() != 2 || a.shape(1) != 3))
    throw py::value_error(std::string(name) + " must have shape (N, 3)");
  const auto* p = reinterpret_cast<const glm::vec3*>(a.data());
  return std::vector<glm::vec3>(p, p + a.size() / 3);
}

template <typename Map>
py::array_t<float> mapPoints(const FloatArrayC& points, const Map& map) {
  std::vector<glm::vec3> p = pointsInput(points, "points");
  for (glm::vec3& q : p) q = map(q);
  return rowsArray(p);
}

void bindGrid(py::module_& m) {
  py::class_<MantaflowGrid> g(
      m, "MantaflowGrid",
      "Where a Mantaflow domain's cells lie in world space: base_res cells, the corner of cell "
      "(0,0,0) at origin, cell_size per axis (Blender stretches the domain box over base_res "
      "cells, so cells are not cubic), and Mantaflow time units per second (2.5).");
  g.def(py::init([](const std::array<int, 3>& res, const std::array<float, 3>& origin,
                    const std::array<float, 3>& cellSize, float unitsPerSecond) {
          MantaflowGrid grid{ivec3Of(res), vec3Of(origin), vec3Of(cellSize), unitsPerSecond};
          grid.validate();
          return grid;
        }),
        py::arg("resolution"), py::arg("origin"), py::arg("cell_size"),
        py::arg("time_units_per_second") = kMantaflowTimeUnitsPerSecond,
        "ValueError on a resolution outside [1, 2048] or a cell size <= 0.");
  g.def_property_readonly("resolution", [](const MantaflowGrid& x) { return vec3Tuple(x.resolution); });
  g.def_property_readonly("origin", [](const MantaflowGrid& x) { return vec3Tuple(x.origin); });
  g.def_property_readonly("cell_size", [](const MantaflowGrid& x) { return vec3Tuple(x.cellSize); });
  g.def_property_readonly("time_units_per_second",
                          [](const MantaflowGrid& x) { return x.timeUnitsPerSecond; });
  g.def_property_readonly("vdb_voxel_size", &MantaflowGrid::vdbVoxelSize,
                          "Voxel size of the cache's VDB transform (longest side / resolution).");
  g.def(
      "index_to_world",
      [](const MantaflowGrid& x, const FloatArrayC& p) {
        return mapPoints(p, [&](glm::vec3 q) { return x.indexToWorld(q); });
      },
      py::arg("points"), "(N, 3) cell coordinates (cell (i,j,k) spans [i, i+1]...) to world.");
  g.def(
      "world_to_index",
      [](const MantaflowGrid& x, const FloatArrayC& p) {
        return mapPoints(p, [&](glm::vec3 q) { return x.worldToIndex(q); });
      },
      py::arg("points"), "(N, 3) world positions to cell coordinates.");
}

void bindFrame(py::module_& m) {
  py::class_<MantaflowFrame> f(
      m, "MantaflowFrame",
      "One Mantaflow frame on its base grid: density at cell centres, face velocities in m/s.");
  f.def_static(
      "empty",
      [](const std::array<int, 3>& r) {
        return MantaflowFrame::empty({r[0], r[1], r[2]});
      },
      py::arg("resolution"), "The state before the first cached frame: all zero.");
  f.def(
      "density", [](const MantaflowFrame& x) { return gridArray(x.density); },
      "Copy of the density, (nx, ny, nz) float32.");
  f.def(
      "velocity",
      [](const MantaflowFrame& x) {
        return macArrays(x.velocity);
      },
      "Copies of the face velocities (u, v, w) in m/s, shaped (nx+1, ny, nz), (nx, ny+1, nz), "
      "(nx, ny, nz+1) as SmokeSolver.get_velocity().");
  f.def("max_cells_per_second", &MantaflowFrame::maxCellsPerSecond, py::arg("grid"),
        "Largest |u_a| / cell_size_a over all faces.");

  m.def(
      "read_mantaflow_frame",
      [](const py::object& path, const MantaflowGrid& grid) {
        return withPath(path, [&](const std::string& p) { return readMantaflowFrame(p, grid); });
      },
      py::arg("path"), py::arg("grid"),
      "Reads density and velocity of a Blender Mantaflow fluid_data_####.vdb onto grid "
      "(staggered velocity face by face, in m/s; faces clipped by Mantaflow next to a stored "
      "cell extrapolated from it). RuntimeError naming the file when it is missing, unreadable "
      "or does not match the grid.");
  m.def(
      "write_mantaflow_volume",
      [](const py::object& path, const MantaflowFrame& frame, const MantaflowGrid& grid,
         int number) {
        withPath(path, [&](const std::string& p) { writeMantaflowVolume(p, frame, grid, number); });
      },
      py::arg("path"), py::arg("frame"), py::arg("grid"), py::arg("frame_number"),
      "Writes the frame as a Plume volume VDB (density, cell-centred velocity where there is "
      "smoke) placed in world space by grid, atomically. RuntimeError naming the path.");
}

void bindTracer(py::module_& m) {
  py::class_<MantaflowTracer> t(
      m, "MantaflowTracer",
      "Streaklines (smoke_surfaces §3.2) advected through a Mantaflow cache: velocity linear in "
      "time between two cached frames, substeps with at most cfl cells each, the midpoint rule "
      "per substep (second order in time); positions in world space.");
  t.def(py::init([](const MantaflowGrid& grid, int emissionPeriod, Interpolation interpolation,
                    const std::array<Boundary, 6>& boundaries, float cfl) {
          MantaflowTraceParams p;
          p.streak.emissionPeriod = emissionPeriod;
          p.streak.interpolation = interpolation;
          p.cfl = cfl;
          return std::make_unique<MantaflowTracer>(p, grid, boundaries);
        }),
        py::arg("grid"), py::arg("emission_period") = 1,
        py::arg("interpolation") = Interpolation::MonotonicCubic,
        py::arg("boundaries") =
            std::array<Boundary, 6>{Boundary::Open, Boundary::Open, Boundary::Open, Boundary::Open,
                                    Boundary::Open, Boundary::Open},
        py::arg("cfl") = 1.f,
        "boundaries: -x, +x, -y, +y, -z, +z (Mantaflow border collisions are CLOSED). ValueError "
        "on emission_period outside [1, 100000] or cfl outside [0.05, 10].");
  t.def(
      "add_point_sources",
      [](MantaflowTracer& x, const FloatArrayC& positions, const std::vector<int>& groups) {
        return x.addPointSources(pointsInput(positions, "positions"), groups);
      },
      py::arg("positions"), py::arg("groups"),
      "Still point sources at world positions (N, 3), candidate group of each (N,); only before "
      "the first frame. ValueError on sizes or positions outside the domain. Returns the first "
      "ID.");
  t.def("substeps", &MantaflowTracer::substeps, py::arg("a"), py::arg("b"), py::arg("frame_dt"),
        "Substeps advance_frame(a, b, frame_dt) takes.");
  t.def(
      "advance_frame",
      [](MantaflowTracer& x, const MantaflowFrame& a, const MantaflowFrame& b, float dt) {
        py::gil_scoped_release release;
        return x.advanceFrame(a, b, dt);
      },
      py::arg("a"), py::arg("b"), py::arg("frame_dt"),
      "One frame of frame_dt seconds from frame a's fields to frame b's. Returns the substeps "
      "taken, 0 when cancel() was called (discard the tracer then). Releases the GIL.");
  t.def(
      "write_snapshot",
      [](const MantaflowTracer& x, const py::object& path) {
        withPath(path, [&](const std::string& p) { writeStreakFile(p, x.snapshot()); });
      },
      py::arg("path"),
      "Writes the streaklines now (world positions) as a streak file, atomically.");
  t.def("cancel", &MantaflowTracer::cancel, "Thread-safe: a running advance_frame() returns 0.");
  t.def_property(
      "emitting", [](const MantaflowTracer& x) { return x.tracer().emitting(); },
      &MantaflowTracer::setEmitting,
      "False pauses emission (smoke_surfaces §3.2, Figure 10): the emission instants reached "
      "while paused add no particles, the others keep moving. Default True.");
  t.def_property_readonly("source_count",
                          [](const MantaflowTracer& x) { return x.tracer().sourceCount(); });
  t.def_property_readonly("particles_per_source",
                          [](const MantaflowTracer& x) { return x.tracer().particlesPerSource(); });
  t.def_property_readonly(
      "steps", [](const MantaflowTracer& x) { return x.tracer().steps(); },
      "Substeps taken so far.");
}

}  // namespace

void bindMantaflow(py::module_& m) {
  bindGrid(m);
  bindFrame(m);
  bindTracer(m);
}

}  // namespace plume::bindings
