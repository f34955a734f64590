/// \file bind_flowgraph_synth.cpp
/// Flow-graph fire, data and synthesis side (graph_fire_synthesis.txt §4.2, §5.2-5.3): the
/// pathline recorder of a fire bake with its file, pathline files, the synthesizer with uniform
/// or grid external velocity, and rasterization into frame VDBs. Conversions and docstrings
/// only; frames, file reads and writes, steps and rasterization release the GIL.

#include "bindings/bindings.h"

#include "flowgraph/fire_raster.h"
#include "flowgraph/pathline_recorder.h"
#include "flowgraph/synthesizer.h"
#include "flowgraph/velocity_field.h"
#include "io/pathline_file.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstring>
#include <memory>

namespace py = pybind11;

namespace plume::bindings {
namespace {

using FloatF = py::array_t<float, py::array::f_style | py::array::forcecast>;
using FloatC = py::array_t<float, py::array::c_style | py::array::forcecast>;

glm::vec3 vec3Arg(const py::object& o, const char* name) {
  const auto v = o.cast<std::vector<float>>();
  if (v.size() != 3) throw py::value_error(std::string(name) + " must hold 3 numbers");
  return {v[0], v[1], v[2]};
}

py::array_t<float> rows3(const std::vector<glm::vec3>& v) {
  py::array_t<float> a({py::ssize_t(v.size()), py::ssize_t(3)});
  if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(glm::vec3));
  return a;
}

py::array_t<float> floats(const std::vector<float>& v) {
  py::array_t<float> a(py::ssize_t(v.size()));
  if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(float));
  return a;
}

/// A 1-D array of linear cell indices as a CellSet (ValueError for negative ones).
CellSet cellsArg(const py::object& o) {
  const auto a = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(o);
  if (!a || a.ndim() != 1) throw py::value_error("fuel_cells must be a 1-D array of cell indices");
  CellSet cells;
  for (py::ssize_t n = 0; n < a.size(); ++n) {
    const long long c = a.data()[n];
    if (c < 0 || c > 0xffffffffLL) throw py::value_error("fuel_cells holds an index outside the grid");
    cells.cells.push_back(std::uint32_t(c));
  }
  return cells;
}

/// A recorder writing its groups to a pathline file as they complete (one per bake).
struct PathlineBake {
  std::unique_ptr<PathlineFileWriter> writer;
  std::unique_ptr<PathlineRecorder> recorder;
};

/// (N, 3) positions, (N,) density and temperature of equal N, viewed for rasterizeFire().
struct ParticleArrays {
  FloatC positions, density, temperature;
  ParticleArrays(const py::object& x, const py::object& r, const py::object& t)
      : positions(FloatC::ensure(x)), density(FloatC::ensure(r)), temperature(FloatC::ensure(t)) {
    if (!positions || positions.ndim() != 2 || positions.shape(1) != 3)
      throw py::value_error("positions must be a float array of shape (N, 3)");
    const py::ssize_t n = positions.shape(0);
    if (!density || density.ndim() != 1 || density.shape(0) != n || !temperature ||
        temperature.ndim() != 1 || temperature.shape(0) != n)
      throw py::value_error("density and temperature must be float arrays of shape (N,) with N = " +
                            std::to_string(n));
  }
  FireParticleView view() const {
    return {reinterpret_cast<const glm::vec3*>(positions.data()), density.data(), temperature.data(),
            std::size_t(positions.shape(0))};
  }
};

/// Calls f(u) with the GIL released, u the external velocity `ext`: None (zero), (ux, uy, uz)
/// or a VelocityField.
template <typename F>
void withExternalVelocity(const py::object& ext, const F& f) {
  if (py::isinstance<GridVelocityField>(ext)) {
    const GridVelocityField& field = ext.cast<const GridVelocityField&>();
    py::gil_scoped_release release;
    f(field);
  } else {
    const glm::vec3 u = ext.is_none() ? glm::vec3(0.f) : vec3Arg(ext, "external_velocity");
    py::gil_scoped_release release;
    f(u);
  }
}

py::dict rasterStats(const FireGrids& g) {
  py::dict d;
  d["voxels"] = g.density->activeVoxelCount();
  return d;
}

void bindRecorder(py::module_& m) {
  py::class_<PathlineParams> p(m, "PathlineParams", "Pathline sampling of a fire bake (§4.2).");
  p.def(py::init([](int nodesPerFrame, float lifetime) {
          PathlineParams s;
          s.nodesPerFrame = nodesPerFrame;
          s.lifetime = lifetime;
          s.validate();
          return s;
        }),
        py::arg("nodes_per_frame") = 2, py::arg("lifetime") = 1.f,
        "ValueError on nodes_per_frame outside [1, 64] or a lifetime that is not > 0 s.");
  p.def_readonly("nodes_per_frame", &PathlineParams::nodesPerFrame,
                 "Node steps per frame: Δt_n = frame_dt / nodes_per_frame. Reproduction is accurate "
                 "when the fastest particles cross about one cell per node step (§4.1: Δt = 0.5 Δx / U).");
  p.def_readonly("lifetime", &PathlineParams::lifetime, "t_max, seconds: L = round(t_max / Δt_n).");
  p.def("samples", &PathlineParams::samples, py::arg("frame_dt"), "L for frames of frame_dt seconds.");

  py::class_<PathlineBake> r(
      m, "PathlineRecorder",
      "Records the pathline groups of a fire bake (§4.2-4.3) into a pathline file while the solver "
      "runs: at every node step Δt_n, |Ω| particles seeded at spacing Δx/2 in the fuel cells, "
      "integrated with RK4 across the solver's substeps, sampled L times. Groups are appended as "
      "they complete; finish() makes the file complete (until then only '<path>.partial' exists).");
  r.def(py::init([](const PathlineParams& params, const SmokeParams& smoke, const py::object& cells,
                    const py::object& path, bool float16) {
          auto bake = std::make_unique<PathlineBake>();
          // The sink reaches the writer through the bake, whose address Python's holder keeps.
          bake->recorder = std::make_unique<PathlineRecorder>(
              params, smoke, cellsArg(cells),
              [raw = bake.get()](const PathlineGroup& g, const std::vector<glm::vec3>&) {
                raw->writer->append(g);
              });
          PathlineFileInfo info;
          info.layout = bake->recorder->layout();
          info.resolution = smoke.resolution;
          info.cellSize = smoke.cellSize;
          info.origin = smoke.origin;
          info.nodesPerFrame = params.nodesPerFrame;
          info.float16 = float16;
          const std::string file = pathArg(path);
          {
            py::gil_scoped_release release;
            bake->writer = std::make_unique<PathlineFileWriter>(file, info);
          }
          return bake;
        }),
        py::arg("params"), py::arg("smoke"), py::arg("fuel_cells"), py::arg("path"),
        py::arg("float16") = false,
        "params: PathlineParams; smoke: the bake's SmokeParams; fuel_cells: linear indices of the "
        "cells where fuel is injected (source_cells() of every fuel source); path: the pathline "
        "file (pathlines.bin in the bake folder). ValueError on bad settings or no fuel cell; "
        "RuntimeError naming the file if it cannot be written.");
  r.def(
      "advance_frame",
      [](PathlineBake& b, SmokeSolver& solver) {
        py::gil_scoped_release release;
        return solver.advanceFrame(b.recorder.get());
      },
      py::arg("solver"),
      "solver.advance_frame() with the recorder following every substep. Releases the GIL. "
      "Returns False when the solver or the recorder was cancelled (discard both).");
  r.def("finish", [](PathlineBake& b) {
          py::gil_scoped_release release;
          b.writer->finish();
        },
        "Writes the node table and renames the file to its path (the groups still young are "
        "dropped: they lack samples).");
  r.def("discard", [](PathlineBake& b) { b.writer->discard(); },
        "Removes the partial file (a cancelled bake).");
  r.def("cancel", [](PathlineBake& b) { b.recorder->cancel(); },
        "Thread-safe: a running advance_frame() returns False before its next step.");
  r.def_property_readonly("layout", [](const PathlineBake& b) { return b.recorder->layout(); });
  r.def_property_readonly("seeds", [](const PathlineBake& b) { return rows3(b.recorder->seeds()); },
                          "Ω: (|Ω|, 3) float32 world positions.");
  r.def_property_readonly("groups_seeded", [](const PathlineBake& b) { return b.recorder->groupsSeeded(); });
  r.def_property_readonly("groups_completed",
                          [](const PathlineBake& b) { return b.recorder->groupsCompleted(); },
                          "Nodes written so far.");
  r.def_property_readonly("path", [](const PathlineBake& b) { return b.writer->path(); });
  r.def_property_readonly("partial_path", [](const PathlineBake& b) { return b.writer->partialPath(); });
}

void bindFile(py::module_& m) {
  py::class_<PathlineFile> f(m, "PathlineFile",
                             "A complete pathline file, read lazily: open() reads its header and "
                             "node table, read_group() one node.");
  f.def_static("open", [](const py::object& path) { return withPath(path, PathlineFile::open); },
               py::arg("path"),
               "RuntimeError naming the file when it is missing, incomplete, truncated or corrupt.");
  f.def_property_readonly("path", &PathlineFile::path);
  f.def_property_readonly("layout", &PathlineFile::layout);
  f.def_property_readonly("node_count", &PathlineFile::nodeCount);
  f.def_property_readonly("bytes_per_node", &PathlineFile::bytesPerNode);
  f.def_property_readonly("float16", [](const PathlineFile& p) { return p.info().float16; });
  f.def_property_readonly("nodes_per_frame", [](const PathlineFile& p) { return p.info().nodesPerFrame; });
  f.def_property_readonly("resolution", [](const PathlineFile& p) {
    const glm::ivec3 r = p.info().resolution;
    return py::make_tuple(r.x, r.y, r.z);
  });
  f.def_property_readonly("cell_size", [](const PathlineFile& p) { return p.info().cellSize; });
  f.def_property_readonly("origin", [](const PathlineFile& p) {
    const glm::vec3 o = p.info().origin;
    return py::make_tuple(o.x, o.y, o.z);
  });
  f.def("read_group", [](const PathlineFile& p, int k, int state) {
          py::gil_scoped_release release;
          return p.readGroup(k, state);
        },
        py::arg("node"), py::arg("state") = 0,
        "Node k as a PathlineGroup (state copied into it). IndexError for a bad k, RuntimeError "
        "naming the file for a corrupt block.");
}

void bindSynthesizer(py::module_& m) {
  py::class_<GridVelocityField> v(m, "VelocityField",
                                  "u_ext on a cell-centred grid (§5.2), e.g. Blender's Wind and "
                                  "Turbulence force fields evaluated by the add-on.");
  v.def(py::init([](const py::object& values, float cellSize, const py::object& origin) {
          const FloatF a = FloatF::ensure(values);
          if (!a || a.ndim() != 4 || a.shape(3) != 3)
            throw py::value_error("values must be a float array of shape (nx, ny, nz, 3)");
          VectorGrid g(glm::ivec3(int(a.shape(0)), int(a.shape(1)), int(a.shape(2))));
          const auto r = a.unchecked<4>();
          for (py::ssize_t k = 0; k < a.shape(2); ++k)
            for (py::ssize_t j = 0; j < a.shape(1); ++j)
              for (py::ssize_t i = 0; i < a.shape(0); ++i)
                g(int(i), int(j), int(k)) = {r(i, j, k, 0), r(i, j, k, 1), r(i, j, k, 2)};
          return GridVelocityField(std::move(g), cellSize, vec3Arg(origin, "origin"));
        }),
        py::arg("values"), py::arg("cell_size"), py::arg("origin"),
        "values[i, j, k] at origin + (i + 1/2, j + 1/2, k + 1/2) cell_size, m/s.");
  v.def("at", [](const GridVelocityField& f, const py::object& x) {
    const glm::vec3 u = f.at(vec3Arg(x, "x"));
    return py::make_tuple(u.x, u.y, u.z);
  });

  py::class_<PreparedGroupCache, std::shared_ptr<PreparedGroupCache>> cache(
      m, "PreparedGroupCache",
      "Least-recently-used cache of prepared pathline groups keyed (state, node step), shared by "
      "the synthesizers of one graph (Synthesizer(layout, threads, cache=...)): synthesizing "
      "again reads no group twice. Not thread-safe: one synthesizer steps at a time.");
  cache.def(py::init<std::size_t>(), py::arg("budget_bytes"));
  cache.def_property_readonly("hits", &PreparedGroupCache::hits);
  cache.def_property_readonly("misses", &PreparedGroupCache::misses);
  cache.def_property_readonly("bytes", &PreparedGroupCache::bytes);
  cache.def_property_readonly("budget", &PreparedGroupCache::budget);
  cache.def_property_readonly("size", &PreparedGroupCache::size);
  cache.def("clear", &PreparedGroupCache::clear, "Drops every group (the counters stay).");

  py::class_<Synthesizer> s(
      m, "Synthesizer",
      "Synthesis by eq. 13 (§5.2): each step, live particles move by their own pathline's "
      "velocity samples (trapezoid) plus u_ext and age by one, those at the end of their lifetime "
      "(L samples) are removed, then the visited node emits its particles at their start positions.");
  s.def(py::init([](const PathlineLayout& layout, int threads, std::size_t cacheBytes) {
          return std::make_unique<Synthesizer>(layout, threads, cacheBytes);
        }),
        py::arg("layout"), py::arg("threads") = 0, py::arg("cache_bytes") = 0,
        "cache_bytes: budget of the least-recently-used cache of prepared groups step_node() keeps "
        "between visits (0: every visit reads its file). ValueError on a bad layout or threads < 0.");
  s.def(py::init([](const PathlineLayout& layout, int threads,
                     std::shared_ptr<PreparedGroupCache> cache) {
          if (!cache) throw std::invalid_argument("cache must be a PreparedGroupCache, not None");
          return std::make_unique<Synthesizer>(layout, threads, std::move(cache));
        }),
        py::arg("layout"), py::arg("threads"), py::arg("cache"),
        "The same, with a cache shared with other synthesizers of the same graph.");
  s.def(
      "step",
      [](Synthesizer& syn, const PathlineGroup& g, const py::object& ext) {
        withExternalVelocity(ext, [&](const auto& u) { syn.step(g, u); });
      },
      py::arg("group"), py::arg("external_velocity") = py::none(),
      "One step emitting `group`; external_velocity: None, (ux, uy, uz) m/s constant over the "
      "step, or a VelocityField. ValueError when the group's layout differs.");
  s.def(
      "step_node",
      [](Synthesizer& syn, const PathlineFile& file, int node, int state, const py::object& ext) {
        withExternalVelocity(ext, [&](const auto& u) { syn.stepNode(file, node, state, u); });
      },
      py::arg("file"), py::arg("node"), py::arg("state") = 0, py::arg("external_velocity") = py::none(),
      "step() emitting node `node` of `file` (the pathline file of state `state`): from the cache "
      "of prepared groups (a hit, no copy) or read from the file (a miss, then cached). Keep one "
      "file per state: (state, node) is the cache key. Same particles with or without the cache.");
  s.def_property_readonly("cache_hits", [](const Synthesizer& syn) { return syn.cache().hits(); },
                          "step_node() calls that found their group in the cache.");
  s.def_property_readonly("cache_misses", [](const Synthesizer& syn) { return syn.cache().misses(); },
                          "step_node() calls that read their group from its file.");
  s.def_property_readonly("cache_bytes", [](const Synthesizer& syn) { return syn.cache().bytes(); },
                          "Bytes of prepared groups held by the cache (<= cache_budget).");
  s.def_property_readonly("cache_budget", [](const Synthesizer& syn) { return syn.cache().budget(); });
  s.def_property_readonly("cached_groups", [](const Synthesizer& syn) { return syn.cache().size(); });
  s.def_property_readonly("layout", &Synthesizer::layout);
  s.def_property_readonly("steps", &Synthesizer::steps);
  s.def_property_readonly("time", &Synthesizer::time, "Synthesis time of the particles, s.");
  s.def_property_readonly("live_groups", &Synthesizer::liveGroups);
  s.def_property_readonly("particle_count", &Synthesizer::particleCount);
  s.def_property_readonly("first_live_step", &Synthesizer::firstLiveStep);
  s.def("particles", [](const Synthesizer& syn) {
          SynthParticles p;
          {
            py::gil_scoped_release release;
            syn.gather(p);
          }
          py::dict d;
          d["positions"] = rows3(p.positions);
          d["density"] = floats(p.density);
          d["temperature"] = floats(p.temperature);
          return d;
        },
        "dict(positions (N, 3), density (N,), temperature (N,)) float32 copies, oldest group first.");
  s.def(
      "write_vdb",
      [](const Synthesizer& syn, const py::object& path, const FireRasterParams& params, int frame) {
        const std::string p = pathArg(path);
        FireGrids grids;
        {
          py::gil_scoped_release release;
          SynthParticles parts;
          syn.gather(parts);
          grids = rasterizeFire({parts.positions.data(), parts.density.data(),
                                 parts.temperature.data(), parts.size()}, params);
          writeFireVdb(p, grids, frame);
        }
        return rasterStats(grids);
      },
      py::arg("path"), py::arg("params"), py::arg("frame"),
      "Rasterizes the live particles (write_fire_vdb) and writes them atomically; returns "
      "dict(voxels=...).");
}

void bindRaster(py::module_& m) {
  py::class_<FireRasterParams> p(m, "FireRasterParams",
                                 "Particles to VDB grids density, temperature, flame (§5.3).");
  p.def(py::init([](float voxelSize, const py::object& origin, float particleVolume, float ambient,
                    float ignition, float maxTemperature, int threads) {
          FireRasterParams r;
          r.voxelSize = voxelSize;
          r.origin = vec3Arg(origin, "origin");
          r.particleVolume = particleVolume;
          r.ambientTemperature = ambient;
          r.ignitionTemperature = ignition;
          r.maxTemperature = maxTemperature;
          r.threads = threads;
          r.validate();
          return r;
        }),
        py::arg("voxel_size"), py::arg("origin") = py::make_tuple(0.f, 0.f, 0.f),
        py::arg("particle_volume") = 0.f, py::arg("ambient_temperature") = 0.f,
        py::arg("ignition_temperature") = 1.f, py::arg("max_temperature") = 4.f,
        py::arg("threads") = 0,
        "voxel_size, origin: the bake's cell size and domain origin; particle_volume: m³ each "
        "particle stands for (0: (voxel_size/2)³); flame = clamp((T - ignition) / (max - "
        "ignition), 0, 1). ValueError on bad values.");
  p.def_readonly("voxel_size", &FireRasterParams::voxelSize);
  p.def_readonly("particle_volume", &FireRasterParams::particleVolume);
  p.def_readonly("ignition_temperature", &FireRasterParams::ignitionTemperature);
  p.def_readonly("max_temperature", &FireRasterParams::maxTemperature);

  m.def(
      "write_fire_vdb",
      [](const py::object& path, const py::object& positions, const py::object& density,
         const py::object& temperature, const FireRasterParams& params, int frame) {
        const ParticleArrays parts(positions, density, temperature);
        const std::string p = pathArg(path);
        FireGrids grids;
        {
          py::gil_scoped_release release;
          grids = rasterizeFire(parts.view(), params);
          writeFireVdb(p, grids, frame);
        }
        return rasterStats(grids);
      },
      py::arg("path"), py::arg("positions"), py::arg("density"), py::arg("temperature"),
      py::arg("params"), py::arg("frame") = 0,
      "Rasterizes particles with OpenVDB's point transfer (trilinear hat; density splatted so "
      "mass is conserved, temperature averaged, flame from temperature) and writes grids "
      "density, temperature, flame to `path` atomically. Returns dict(voxels=...).");
}

}  // namespace

void bindFlowgraphSynth(py::module_& m) {
  bindRecorder(m);
  bindFile(m);
  bindSynthesizer(m);
  bindRaster(m);
}

}  // namespace plume::bindings
