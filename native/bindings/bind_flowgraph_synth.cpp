/// \file bind_flowgraph_synth.cpp
/// Flow-graph fire, synthesis side ([Graph Fire Synthesis] §5.2-5.3): the synthesizer with
/// uniform or grid external velocity, its cache of prepared groups, and rasterization into frame
/// VDBs (the pathline recorder and files it reads are in bind_flowgraph_pathlines.cpp).
/// Conversions and docstrings only; steps, file reads and writes and rasterization release the GIL.

#include "bindings/bindings.h"
#include "bindings/convert.h"

#include "fields/fire_raster.h"
#include "flowgraph/synthesizer.h"
#include "fields/velocity_field.h"
#include "flowgraph/pathline_file.h"

#include <pybind11/stl.h>

#include <memory>

namespace py = pybind11;

namespace plume::bindings {
namespace {

/// (N, 3) positions, (N,) density and temperature of equal N, viewed for rasterizeFire().
struct ParticleArrays {
  FloatArrayC positions, density, temperature;
  ParticleArrays(const py::object& x, const py::object& r, const py::object& t)
      : positions(FloatArrayC::ensure(x)), density(FloatArrayC::ensure(r)), temperature(FloatArrayC::ensure(t)) {
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

/// What write_vdb() and write_fire_vdb() return: dict(voxels=active voxels of the density).
py::dict rasterStats(const FireGrids& g) {
  py::dict d;
  d["voxels"] = g.density->activeVoxelCount();
  return d;
}

void bindSynthesizer(py::module_& m) {
  py::class_<GridVelocityField> v(m, "VelocityField",
                                  "u_ext on a cell-centred grid (§5.2), e.g. Blender's Wind and "
                                  "Turbulence force fields evaluated by the add-on.");
  v.def(py::init([](const py::object& values, float cellSize, const py::object& origin) {
          const FloatArrayF a = FloatArrayF::ensure(values);
          if (!a || a.ndim() != 4 || a.shape(3) != 3)
            throw py::value_error("values must be a float array of shape (nx, ny, nz, 3)");
          return GridVelocityField(vectorGridOf(a), cellSize, vec3Arg(origin, "origin"));
        }),
        py::arg("values"), py::arg("cell_size"), py::arg("origin"),
        "values[i, j, k] at origin + (i + 1/2, j + 1/2, k + 1/2) cell_size, m/s.");
  v.def("at", [](const GridVelocityField& f, const py::object& x) { return vec3Tuple(f.at(vec3Arg(x, "x"))); });

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
  s.def_property(
      "emitter_transform",
      [](const Synthesizer& syn) {
        DoubleArrayC a({4, 4});
        const glm::mat4& m = syn.emitterTransform();
        for (int row = 0; row < 4; ++row)
          for (int col = 0; col < 4; ++col) a.mutable_at(row, col) = m[col][row];
        return a;
      },
      [](Synthesizer& syn, const DoubleArrayC& m) { syn.setEmitterTransform(matrixArg(m, "emitter_transform")); },
      "E, 4x4 row-major: the placement of the groups emitted from now on (the fire attached to a "
      "moving object, §5.2's fire blade): they start at E x_0 and keep their pathlines' world-space "
      "motion. Identity: where they were recorded. ValueError unless finite and affine.");
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
          d["positions"] = rowsArray(p.positions);
          d["density"] = array1D(p.density);
          d["temperature"] = array1D(p.temperature);
          d["velocity"] = rowsArray(p.velocity);
          return d;
        },
        "dict(positions (N, 3), density (N,), temperature (N,), velocity (N, 3)) float32 copies, oldest "
        "group first.");
  s.def(
      "write_vdb",
      [](const Synthesizer& syn, const py::object& path, const FireRasterParams& params, int frame) {
        return rasterStats(withPath(path, [&](const std::string& p) {
          SynthParticles parts;
          syn.gather(parts);
          const FireGrids grids = rasterizeFire({parts.positions.data(), parts.density.data(),
                                                 parts.temperature.data(), parts.size(), parts.velocity.data()},
                                                params);
          writeFireVdb(p, grids, frame);
          return grids;
        }));
      },
      py::arg("path"), py::arg("params"), py::arg("frame"),
      "Rasterizes the live particles (write_fire_vdb, with their velocity grid) and writes them "
      "atomically; returns dict(voxels=...).");
}

void bindRaster(py::module_& m) {
  py::class_<FireRasterParams> p(m, "FireRasterParams",
                                 "Particles to VDB grids density, temperature, flame (§5.3).");
  p.def(py::init([](float voxelSize, const py::object& origin, float particleVolume, float ambient,
                    float ignition, float maxTemperature, int threads, float spacingScale,
                    float maxSplatRadius, float sheetInterval) {
          FireRasterParams r;
          r.voxelSize = voxelSize;
          r.origin = vec3Arg(origin, "origin");
          r.particleVolume = particleVolume;
          r.ambientTemperature = ambient;
          r.ignitionTemperature = ignition;
          r.maxTemperature = maxTemperature;
          r.threads = threads;
          r.spacingScale = spacingScale;
          r.maxSplatRadius = maxSplatRadius;
          r.sheetInterval = sheetInterval;
          r.validate();
          return r;
        }),
        py::arg("voxel_size"), py::arg("origin") = py::make_tuple(0.f, 0.f, 0.f),
        py::arg("particle_volume") = 0.f, py::arg("ambient_temperature") = 0.f,
        py::arg("ignition_temperature") = 1.f, py::arg("max_temperature") = 4.f,
        py::arg("threads") = 0, py::arg("spacing_scale") = 1.f, py::arg("max_splat_radius") = 4.f,
        py::arg("sheet_interval") = 0.f,
        "voxel_size, origin: the bake's cell size and domain origin; particle_volume: m³ each "
        "particle stands for (0: (voxel_size/2)³); flame = clamp((T - ignition) / (max - "
        "ignition), 0, 1); spacing_scale: κ, the splat radius is κ times the local particle spacing "
        "(at least one voxel, at most max_splat_radius voxels; 0: the trilinear hat); "
        "sheet_interval: Δt_n, s, between emitted sheets of particles: with velocities the "
        "radius also covers |u| Δt_n. ValueError on bad values.");
  p.def_readonly("voxel_size", &FireRasterParams::voxelSize);
  p.def_readonly("particle_volume", &FireRasterParams::particleVolume);
  p.def_readonly("ignition_temperature", &FireRasterParams::ignitionTemperature);
  p.def_readonly("max_temperature", &FireRasterParams::maxTemperature);
  p.def_readonly("spacing_scale", &FireRasterParams::spacingScale);
  p.def_readonly("max_splat_radius", &FireRasterParams::maxSplatRadius);
  p.def_readonly("sheet_interval", &FireRasterParams::sheetInterval);

  m.def(
      "write_fire_vdb",
      [](const py::object& path, const py::object& positions, const py::object& density,
         const py::object& temperature, const FireRasterParams& params, int frame) {
        const ParticleArrays parts(positions, density, temperature);
        return rasterStats(withPath(path, [&](const std::string& p) {
          const FireGrids grids = rasterizeFire(parts.view(), params);
          writeFireVdb(p, grids, frame);
          return grids;
        }));
      },
      py::arg("path"), py::arg("positions"), py::arg("density"), py::arg("temperature"),
      py::arg("params"), py::arg("frame") = 0,
      "Rasterizes particles with OpenVDB's point transfer (tent kernels sized by the particle spacing; density splatted so "
      "mass is conserved, temperature averaged, flame from temperature) and writes grids "
      "density, temperature, flame to `path` atomically. Returns dict(voxels=...).");
}

}  // namespace

void bindFlowgraphSynth(py::module_& m) {
  bindFlowgraphPathlines(m);
  bindSynthesizer(m);
  bindRaster(m);
}

}  // namespace plume::bindings
