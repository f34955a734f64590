/// \file bind_streak.cpp
/// Streaklines for Python (smoke_surfaces.txt §3.2): point sources, the tracer and the
/// per-frame streak files (their clustering, §3.3, is in bind_streak_clusters.cpp).
/// Conversions and docstrings only; long calls release the GIL.

#include "bindings/bindings.h"
#include "bindings/streak_frames.h"

#include "io/streak_file.h"
#include "io/tracer_state_file.h"
#include "solver/emitters.h"
#include "solver/smoke_solver.h"
#include "tracers/point_sources.h"
#include "tracers/streak_tracer.h"
#include "tracers/tracer_driver.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstring>
#include <sstream>

namespace py = pybind11;

namespace plume::bindings {
namespace {

using FloatC = py::array_t<float, py::array::c_style | py::array::forcecast>;
using FloatF = py::array_t<float, py::array::f_style | py::array::forcecast>;
using DoubleC = py::array_t<double, py::array::c_style | py::array::forcecast>;
using LongC = py::array_t<long long, py::array::c_style | py::array::forcecast>;

std::string shapeOf(const py::array& a) {
  std::ostringstream s;
  s << "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) s << (d ? ", " : "") << a.shape(d);
  s << (a.ndim() == 1 ? ",)" : ")");
  return s.str();
}

glm::vec3 toVec3(const py::object& o, const char* name) {
  if (!py::isinstance<py::sequence>(o) || py::len(o) != 3)
    throw py::value_error(std::string(name) + " must be a sequence of 3 numbers");
  py::sequence s = py::reinterpret_borrow<py::sequence>(o);
  return {s[0].cast<float>(), s[1].cast<float>(), s[2].cast<float>()};
}

/// (N, 3) float array as points; an empty array gives no points.
std::vector<glm::vec3> toPoints(const FloatC& a, const char* name) {
  if (a.size() == 0) return {};
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error(std::string(name) + " must have shape (N, 3), got " + shapeOf(a));
  std::vector<glm::vec3> p(std::size_t(a.shape(0)));
  std::memcpy(p.data(), a.data(), p.size() * sizeof(glm::vec3));
  return p;
}

/// An object as a NumPy array of T (ValueError naming it if it cannot be converted).
template <typename A>
A ensureArray(const py::object& o, const std::string& name) {
  A a = A::ensure(o);
  if (!a) {
    PyErr_Clear();
    throw py::value_error(name + " must be a numeric array");
  }
  return a;
}

glm::ivec3 toIVec3(const py::object& o, const char* name) {
  if (!py::isinstance<py::sequence>(o) || py::len(o) != 3)
    throw py::value_error(std::string(name) + " must be a sequence of 3 integers");
  py::sequence s = py::reinterpret_borrow<py::sequence>(o);
  glm::ivec3 r;
  for (int a = 0; a < 3; ++a) {
    const long long v = s[std::size_t(a)].cast<long long>();
    if (v < 1 || v > 1 << 20) throw py::value_error(std::string(name) + " must be in [1, 1048576] per axis");
    r[a] = int(v);
  }
  return r;
}

/// 1-D integer array as ints (ValueError outside the int range).
std::vector<int> toInts(const LongC& a, const char* name) {
  if (a.size() == 0) return {};
  if (a.ndim() != 1)
    throw py::value_error(std::string(name) + " must be one-dimensional, got " + shapeOf(a));
  std::vector<int> v(std::size_t(a.shape(0)));
  for (std::size_t n = 0; n < v.size(); ++n) {
    const long long x = a.data()[n];
    if (x < -2147483648LL || x > 2147483647LL)
      throw py::value_error(std::string(name) + " holds " + std::to_string(x) + ", outside int32");
    v[n] = int(x);
  }
  return v;
}

py::array_t<float> pointsToNumpy(const std::vector<glm::vec3>& p) {
  py::array_t<float> a({py::ssize_t(p.size()), py::ssize_t(3)});
  if (!p.empty()) std::memcpy(a.mutable_data(), p.data(), p.size() * sizeof(glm::vec3));
  return a;
}

template <typename T, typename S>
py::array_t<T> vectorToNumpy(const std::vector<S>& v) {
  py::array_t<T> a(py::ssize_t(v.size()));
  for (std::size_t n = 0; n < v.size(); ++n) a.mutable_data()[n] = T(v[n]);
  return a;
}

// --- streak frames ------------------------------------------------------------------------

/// A snapshot-like dict as a StreakFrame. counts and positions are required; density too when
/// `needDensity`; groups and outside default to zeros. With `positionsOnly`, density and outside
/// are neither read nor filled (empty), for code that reads counts, positions and groups only.
StreakFrame toFrame(const py::handle& obj, bool needDensity, const std::string& what,
                    bool positionsOnly = false) {
  if (!py::isinstance<py::dict>(obj))
    throw py::value_error(what + " must be a dict with counts, positions, density");
  py::dict d = py::reinterpret_borrow<py::dict>(obj);
  auto get = [&](const char* key, bool required) -> py::object {
    if (d.contains(key)) return d[key];
    if (required) throw py::value_error(what + " has no '" + key + "'");
    return py::none();
  };
  StreakFrame f;
  f.counts = toInts(ensureArray<LongC>(get("counts", true), what + ": counts"), "counts");
  f.positions = toPoints(ensureArray<FloatC>(get("positions", true), what + ": positions"), "positions");
  const std::size_t m = f.positions.size();
  if (positionsOnly) {
    const py::object groups = get("groups", false);
    f.groups = groups.is_none() ? std::vector<int>(f.counts.size(), 0)
                                : toInts(ensureArray<LongC>(groups, what + ": groups"), "groups");
    std::size_t total = 0;
    for (int c : f.counts) {
      if (c < 0) throw py::value_error(what + ": counts hold " + std::to_string(c) + " (negative)");
      total += std::size_t(c);
    }
    if (f.groups.size() != f.counts.size())
      throw py::value_error(what + ": " + std::to_string(f.groups.size()) + " groups for " +
                            std::to_string(f.counts.size()) + " sources");
    if (m != total)
      throw py::value_error(what + ": counts sum to " + std::to_string(total) + " particles but there are " +
                            std::to_string(m) + " positions");
    return f;
  }
  const py::object density = get("density", needDensity);
  if (density.is_none()) {
    f.density.assign(m, 0.f);
  } else {
    FloatC a = ensureArray<FloatC>(density, what + ": density");
    if (a.ndim() != 1) throw py::value_error(what + ": density must be one-dimensional");
    f.density.assign(a.data(), a.data() + a.size());
  }
  const py::object groups = get("groups", false);
  f.groups = groups.is_none() ? std::vector<int>(f.counts.size(), 0)
                              : toInts(ensureArray<LongC>(groups, what + ": groups"), "groups");
  const py::object outside = get("outside", false);
  if (outside.is_none()) {
    f.outside.assign(m, 0);
  } else {
    auto a = ensureArray<py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>>(
        outside, what + ": outside");
    if (a.ndim() != 1) throw py::value_error(what + ": outside must be one-dimensional");
    f.outside.assign(a.data(), a.data() + a.size());
    for (std::uint8_t& o : f.outside) o = o ? 1 : 0;
  }
  f.validate();  // std::invalid_argument -> ValueError
  return f;
}


py::dict frameToDict(const StreakFrame& f) {
  py::dict d;
  d["counts"] = vectorToNumpy<std::int32_t>(f.counts);
  d["positions"] = pointsToNumpy(f.positions);
  d["density"] = vectorToNumpy<float>(f.density);
  d["groups"] = vectorToNumpy<std::int32_t>(f.groups);
  d["outside"] = vectorToNumpy<bool>(f.outside);
  return d;
}

// --- grids ----------------------------------------------------------------------------------

void toScalarGrid(const FloatF& a, glm::ivec3 n, ScalarGrid& g, const std::string& name) {
  if (a.ndim() != 3 || a.shape(0) != n.x || a.shape(1) != n.y || a.shape(2) != n.z) {
    std::ostringstream s;
    s << name << " must have shape (" << n.x << ", " << n.y << ", " << n.z << "), got " << shapeOf(a);
    throw py::value_error(s.str());
  }
  g.resize(n);
  std::memcpy(g.data(), a.data(), g.count() * sizeof(float));
}

/// (u, v, w) face arrays, as solver.get_velocity() returns them, into a MAC grid of `cells`.
void toMac(const py::object& uvw, glm::ivec3 cells, MacGrid3& mac, const char* name) {
  if (!py::isinstance<py::sequence>(uvw) || py::len(uvw) != 3)
    throw py::value_error(std::string(name) + " must be a tuple (u, v, w)");
  py::sequence s = py::reinterpret_borrow<py::sequence>(uvw);
  mac.resize(cells);
  static const char* kComp[3] = {"u", "v", "w"};
  for (int a = 0; a < 3; ++a) {
    glm::ivec3 size = cells;
    size[a] += 1;
    toScalarGrid(ensureArray<FloatF>(s[std::size_t(a)], std::string(name) + " " + kComp[a]), size, mac.component(a),
                 std::string(name) + " " + kComp[a]);
  }
}

// --- meshes (as SmokeSolver.add_source takes them) ------------------------------------------

glm::mat4 toMat4(const DoubleC& a, const char* name) {
  if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
    throw py::value_error(std::string(name) + " must be a 4x4 matrix, got shape " + shapeOf(a));
  glm::mat4 m;
  // Row-major numpy (world = M @ [x, y, z, 1]) to column-major glm.
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) m[col][row] = float(a.data()[row * 4 + col]);
  return m;
}

EmitterMesh toEmitterMesh(const FloatC& vertices, const LongC& triangles, const DoubleC& matrix,
                          const DoubleC& matrixNext, const std::string& name) {
  EmitterMesh mesh;
  mesh.name = name;
  mesh.vertices = toPoints(vertices, "vertices");
  if (triangles.size() != 0 && (triangles.ndim() != 2 || triangles.shape(1) != 3))
    throw py::value_error("triangles of '" + name + "' must have shape (M, 3), got " +
                          shapeOf(triangles));
  const std::size_t nt = triangles.size() == 0 ? 0 : std::size_t(triangles.shape(0));
  mesh.triangles.resize(nt);
  for (std::size_t n = 0; n < 3 * nt; ++n) {
    const long long t = triangles.data()[n];
    if (t < 0 || t >= (long long)mesh.vertices.size())
      throw py::value_error("triangles of '" + name + "' index vertex " + std::to_string(t) +
                            ", outside [0, " + std::to_string(mesh.vertices.size()) + ")");
    mesh.triangles[n / 3][int(n % 3)] = int(t);
  }
  mesh.matrix = toMat4(matrix, "matrix");
  mesh.matrixNext = toMat4(matrixNext, "matrix_next");
  return mesh;
}

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
      [](StreakTracer& t, const FloatC& positions, const LongC& groups, const py::object& velocities) {
        const std::vector<glm::vec3> p = toPoints(positions, "positions");
        std::vector<int> g = toInts(groups, "groups");
        std::vector<glm::vec3> v;
        if (!velocities.is_none())
          v = toPoints(ensureArray<FloatC>(velocities, "velocities"), "velocities");
        return t.addPointSources(p, g, v);
      },
      py::arg("positions"), py::arg("groups"), py::arg("velocities") = py::none(),
      "Adds point sources: positions (N, 3) world, groups (N,) candidate group of each, "
      "velocities (N, 3) or None (still). Source IDs follow the order added; returns the first "
      "new ID. Only before the first step; ValueError on bad sizes or positions outside the "
      "domain. Emits each source's first particle.");
  c.def(
      "step",
      [](StreakTracer& t, const py::object& before, const py::object& after, const FloatF& density,
         float dt) {
        const glm::ivec3 n = t.gridFrame().resolution;
        MacGrid3 b, a;
        ScalarGrid d;
        toMac(before, n, b, "before");
        toMac(after, n, a, "after");
        toScalarGrid(density, n, d, "density");
        py::gil_scoped_release release;
        t.step(b, a, d, dt);
      },
      py::arg("before"), py::arg("after"), py::arg("density"), py::arg("dt"),
      "One step of length dt from the face velocities (u, v, w) at its start and end (shapes as "
      "SmokeSolver.get_velocity()) and the density (nx, ny, nz) at its end.");
  c.def("snapshot", [](const StreakTracer& t) { return frameToDict(t.snapshot()); },
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
        const std::string p = pathArg(path);
        py::gil_scoped_release release;
        writeTracerState(p, t, frame);
      },
      py::arg("path"), py::arg("frame"),
      "Writes a checkpoint (point sources, particles, density, outside flags, exit velocities, "
      "emission count, steps, the emitting switch and settings) labelled with `frame`, atomically. RuntimeError "
      "naming the path if it cannot be written.");
  c.def(
      "load_state",
      [](StreakTracer& t, const py::object& path) {
        const std::string p = pathArg(path);
        py::gil_scoped_release release;
        return readTracerState(p, t);
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

std::vector<StreakFrame> toStreakFrames(const py::sequence& snapshots, bool positionsOnly) {
  std::vector<StreakFrame> out;
  out.reserve(std::size_t(py::len(snapshots)));
  for (std::size_t t = 0; t < std::size_t(py::len(snapshots)); ++t)
    out.push_back(toFrame(snapshots[t], false, "snapshot " + std::to_string(t), positionsOnly));
  return out;
}

std::vector<int> toIntVector(const py::object& values, const std::string& name) {
  return toInts(ensureArray<LongC>(values, name), name.c_str());
}

void bindStreak(py::module_& m) {
  m.def(
      "random_points_in_cells",
      [](const LongC& cells, const py::object& resolution, float cellSize, const py::object& origin,
         int pointsPerCell, std::uint64_t seed, std::uint64_t stream) {
        CellSet set;
        for (int c : toInts(cells, "cells")) {
          if (c < 0) throw py::value_error("cells must hold linear indices >= 0");
          set.cells.push_back(std::uint32_t(c));
        }
        const glm::ivec3 res = toIVec3(resolution, "resolution");
        return pointsToNumpy(
            randomPointsInCells(set, res, cellSize, toVec3(origin, "origin"), pointsPerCell, seed, stream));
      },
      py::arg("cells"), py::arg("resolution"), py::arg("cell_size"), py::arg("origin"),
      py::arg("points_per_cell"), py::arg("seed"), py::arg("stream") = 0,
      "smoke_surfaces §3.2: points_per_cell random world positions uniform in each cell (linear "
      "indices i + nx*(j + ny*k)); point n lies in cells[n // points_per_cell]. float32 (N, 3), "
      "deterministic for (seed, stream).");
  m.def(
      "source_cells",
      [](const FloatC& v, const LongC& t, const DoubleC& matrix, const DoubleC& matrixNext,
         const SmokeParams& p, const std::string& name) {
        const EmitterMesh mesh = toEmitterMesh(v, t, matrix, matrixNext, name);
        const GridFrame grid{p.resolution, p.cellSize, p.origin, p.frameDt};
        CellSet cells;
        {
          py::gil_scoped_release release;
          cells = voxelizeSource(mesh, grid);
        }
        py::array_t<std::uint32_t> c(py::ssize_t(cells.cells.size()));
        if (!cells.cells.empty())
          std::memcpy(c.mutable_data(), cells.cells.data(), cells.cells.size() * 4);
        std::vector<glm::vec3> vel = cells.velocity;
        if (vel.empty()) vel.assign(cells.cells.size(), glm::vec3(0.f));
        return py::make_tuple(c, pointsToNumpy(vel));
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
        const StreakFrame f = toFrame(snapshot, true, "snapshot");
        const std::string p = pathArg(path);
        py::gil_scoped_release release;
        writeStreakFile(p, f);
      },
      py::arg("path"), py::arg("snapshot"),
      "Writes a snapshot dict (counts, positions, density; groups and outside optional) as a "
      "streak file, atomically. ValueError on inconsistent sizes, RuntimeError naming the path "
      "if it cannot be written.");
  m.def(
      "read_streak_file",
      [](const py::object& path) {
        const std::string p = pathArg(path);
        StreakFrame f;
        {
          py::gil_scoped_release release;
          f = readStreakFile(p);
        }
        return frameToDict(f);
      },
      py::arg("path"),
      "Reads a streak file into a snapshot dict. RuntimeError naming the path if it is missing, "
      "truncated or corrupt.");
  m.def("streak_file_name", &streakFileName, py::arg("frame"), "'streaks_0007.bin' for frame 7.");
}

}  // namespace plume::bindings
