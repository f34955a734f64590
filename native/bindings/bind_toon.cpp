/// \file bind_toon.cpp
/// Toon smoke (cartoon_smoke.txt): ToonParams, the fields of a frame, ToonParticles
/// driven by NumPy fields or by Plume volume frames, stencil billboards (Figure 4), the
/// depth-differences reference filter (§2.2) and the toon cache files. Conversions and docstrings
/// only; frames, file reads and writes, billboards and the filter release the GIL.

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>

#include "bindings/bindings.h"
#include "io/toon_file.h"
#include "io/toon_volume.h"
#include "toon/billboard.h"
#include "toon/depth_differences.h"
#include "toon/toon_particles.h"

namespace py = pybind11;

namespace plume::bindings {
namespace {

using FloatF = py::array_t<float, py::array::f_style | py::array::forcecast>;
using FloatC = py::array_t<float, py::array::c_style | py::array::forcecast>;
using DoubleC = py::array_t<double, py::array::c_style | py::array::forcecast>;
using IntC = py::array_t<int, py::array::c_style | py::array::forcecast>;

GridFrame gridArg(const std::array<int, 3>& res, const std::array<float, 3>& origin, float cell) {
  GridFrame g{glm::ivec3(res[0], res[1], res[2]), cell, glm::vec3(origin[0], origin[1], origin[2]),
              1.f / 24.f};
  validateToonGrid(g);
  return g;
}

/// An (nx, ny, nz) array indexed [i, j, k] into a grid of `n` cells (x fastest in memory).
void fieldArg(const py::handle& o, glm::ivec3 n, ScalarGrid& g, const std::string& name) {
  const FloatF a = FloatF::ensure(o);
  if (!a || a.ndim() != 3 || a.shape(0) != n.x || a.shape(1) != n.y || a.shape(2) != n.z)
    throw py::value_error(name + " must be a float array of shape (" + std::to_string(n.x) + ", " +
                          std::to_string(n.y) + ", " + std::to_string(n.z) + ")");
  g.resize(n);
  std::memcpy(g.data(), a.data(), g.count() * sizeof(float));
}

ToonFields fieldsArg(const py::handle& density, const py::sequence& velocity,
                     const py::object& temperature) {
  const FloatF d = FloatF::ensure(density);
  if (!d || d.ndim() != 3) throw py::value_error("density must be a 3-D float array (nx, ny, nz)");
  const glm::ivec3 n(int(d.shape(0)), int(d.shape(1)), int(d.shape(2)));
  if (py::len(velocity) != 3) throw py::value_error("velocity must be a tuple (u, v, w)");
  ToonFields f;
  fieldArg(d, n, f.density, "density");
  f.velocity.resize(n);
  static const char* kNames[3] = {"velocity u", "velocity v", "velocity w"};
  for (int a = 0; a < 3; ++a) {
    glm::ivec3 faces = n;
    faces[a] += 1;
    fieldArg(velocity[std::size_t(a)], faces, f.velocity.component(a), kNames[a]);
  }
  if (!temperature.is_none()) fieldArg(temperature, n, f.temperature, "temperature");
  return f;
}

/// (N, 3) points or cells; None or an empty array gives none.
template <typename T, typename Array>
std::vector<T> tripletsArg(const py::object& o, const char* name) {
  if (o.is_none()) return {};
  const Array a = Array::ensure(o);
  if (!a) throw py::value_error(std::string(name) + " must be an (N, 3) array");
  if (a.size() == 0) return {};
  if (a.ndim() != 2 || a.shape(1) != 3) throw py::value_error(std::string(name) + " must have shape (N, 3)");
  std::vector<T> v(std::size_t(a.shape(0)));
  static_assert(sizeof(T) == 3 * sizeof(typename Array::value_type), "packed triplets");
  std::memcpy(v.data(), a.data(), v.size() * sizeof(T));
  return v;
}

ToonSources sourcesArg(const py::object& cells, const py::object& points) {
  return ToonSources{tripletsArg<glm::ivec3, IntC>(cells, "source_cells"),
                     tripletsArg<glm::vec3, FloatC>(points, "source_points")};
}

template <typename T>
py::array_t<T> vectorResult(const std::vector<T>& v) {
  py::array_t<T> a(py::ssize_t(v.size()));
  if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(T));
  return a;
}

py::array_t<float> pointsResult(const std::vector<glm::vec3>& p) {
  py::array_t<float> a({py::ssize_t(p.size()), py::ssize_t(3)});
  if (!p.empty()) std::memcpy(a.mutable_data(), p.data(), p.size() * sizeof(glm::vec3));
  return a;
}

py::dict stateResult(const ToonParticleState& s) {
  py::dict d;
  d["frame"] = s.frame;
  d["next_id"] = s.nextId;
  d["ids"] = vectorResult(s.ids);
  d["positions"] = pointsResult(s.positions);
  d["velocities"] = pointsResult(s.velocities);
  d["density"] = vectorResult(s.density);
  d["temperature"] = vectorResult(s.temperature);
  d["size"] = vectorResult(s.size);
  d["target_size"] = vectorResult(s.targetSize);
  d["color"] = vectorResult(s.color);
  d["age"] = vectorResult(s.age);
  return d;
}

ToonCamera cameraArg(const DoubleC& m, bool perspective) {
  if (m.ndim() != 2 || m.shape(0) != 4 || m.shape(1) != 4)
    throw py::value_error("camera_matrix must be a 4x4 matrix (the camera's matrix_world)");
  ToonCamera c;
  for (int row = 0; row < 4; ++row)  // row-major NumPy to column-major glm
    for (int col = 0; col < 4; ++col) c.matrixWorld[col][row] = m.data()[row * 4 + col];
  c.perspective = perspective;
  return c;
}

py::dict billboardsResult(const Billboards& b) {
  py::dict d;
  d["angle"] = vectorResult(b.angle);
  d["stretch"] = vectorResult(b.stretch);
  d["axis"] = pointsResult(b.axis);
  return d;
}

/// ToonParticles with the volume frames it last read (a frame-by-frame walk reads each once).
struct ToonSession {
  ToonParticles particles;
  ToonVolumeCache volumes;
};

void bindParams(py::module_& m) {
  py::enum_<ToonIntegration>(m, "ToonIntegration",
                             "Advection of toon particles per substep: EULER (§2.1) or MIDPOINT.")
      .value("EULER", ToonIntegration::Euler)
      .value("MIDPOINT", ToonIntegration::Midpoint);
  py::enum_<ToonColorDriver>(m, "ToonColorDriver",
                             "What drives the colour ramp (§2.3): DENSITY, TEMPERATURE or SPEED.")
      .value("DENSITY", ToonColorDriver::Density)
      .value("TEMPERATURE", ToonColorDriver::Temperature)
      .value("SPEED", ToonColorDriver::Speed);
  py::class_<ToonParams> c(m, "ToonParams",
                           "Settings of the toon particles (cartoon_smoke §2.1-2.3). Sizes in "
                           "metres (stencil diameter), speeds in m/s, densities in field units.");
  c.def(py::init<>());
  c.def_readwrite("emission_count", &ToonParams::emissionCount,
                  "Particles emitted per frame at the source, over its cells/points in turn.");
  c.def_readwrite("birth_density", &ToonParams::birthDensity,
                  "rho_birth: an empty cell denser than this gets a particle (> death_density).");
  c.def_readwrite("birth_spacing", &ToonParams::birthSpacing,
                  "sigma: a newborn is kept only when no particle lies closer than sigma times the "
                  "stencil size of its cell's density, in [0, 10]; 0 = every empty dense cell.");
  c.def_readwrite("death_density", &ToonParams::deathDensity,
                  "rho_death: a particle in thinner smoke shrinks to 0, then is removed.");
  c.def_readwrite("ramp_density_low", &ToonParams::rampDensityLow, "d0 of the size ramp.");
  c.def_readwrite("ramp_density_high", &ToonParams::rampDensityHigh, "d1 of the size ramp (> d0).");
  c.def_readwrite("size_low", &ToonParams::sizeLow, "s0: size at density <= d0 (m).");
  c.def_readwrite("size_high", &ToonParams::sizeHigh, "s1: size at density >= d1 (m).");
  c.def_readwrite("max_size_change", &ToonParams::maxSizeChange,
                  "Largest size change per frame, fraction of max(s0, s1), in [1e-4, 1].");
  c.def_readwrite("max_count", &ToonParams::maxCount, "Particle budget (emission, then birth stop).");
  c.def_readwrite("integration", &ToonParams::integration, "ToonIntegration.EULER or MIDPOINT.");
  c.def_readwrite("cfl", &ToonParams::cfl, "Most cells crossed per substep, in [0.05, 10].");
  c.def_readwrite("seed", &ToonParams::seed, "Seed of the birth and emission positions.");
  c.def_readwrite("stretch_factor", &ToonParams::stretchFactor,
                  "k in stretch = 1 + k |v_screen| (s/m, Figure 4).");
  c.def_readwrite("color_driver", &ToonParams::colorDriver, "ToonColorDriver of the colour ramp.");
  c.def_readwrite("color_low", &ToonParams::colorLow, "Driver value mapped to colour 0.");
  c.def_readwrite("color_high", &ToonParams::colorHigh, "Driver value mapped to colour 1 (> low).");
  c.def_readwrite("threads", &ToonParams::threads, "Worker threads; 0 = all cores.");
  c.def("validate", &ToonParams::validate, "ValueError naming the setting and its range.");
  c.def("ramp_size", &ToonParams::rampSize, py::arg("density"), "§2.3 size ramp.");
}

void bindFields(py::module_& m) {
  py::class_<ToonFields> f(m, "ToonFields",
                           "One frame of a baked cache: density, temperature (optional) at cell "
                           "centres, face velocities in m/s.");
  f.def(py::init([](const py::object& density, const py::sequence& velocity,
                    const py::object& temperature) { return fieldsArg(density, velocity, temperature); }),
        py::arg("density"), py::arg("velocity"), py::arg("temperature") = py::none(),
        "density (nx, ny, nz) indexed [i, j, k], velocity (u, v, w) of shapes (nx+1, ny, nz), "
        "(nx, ny+1, nz), (nx, ny, nz+1) as SmokeSolver.get_velocity(), temperature like density "
        "or None.");
  f.def_static(
      "from_vdb",
      [](const py::object& path, const std::array<int, 3>& res, const std::array<float, 3>& origin,
         float cell, bool resample) {
        const GridFrame g = gridArg(res, origin, cell);
        return withPath(path, [&](const std::string& p) {
          return resample ? resampleToonFields(p, g) : readToonFields(p, g);
        });
      },
      py::arg("path"), py::arg("resolution"), py::arg("origin"), py::arg("cell_size"),
      py::arg("resample") = false,
      "Reads a Plume volume_####.vdb onto the bake's grid (RuntimeError naming the file when it "
      "is missing, unreadable or of another domain). resample: interpolate a volume whose "
      "voxels are not the grid's cells (a traced Mantaflow bake) onto the grid.");
  f.def_property_readonly("resolution", [](const ToonFields& x) {
    const glm::ivec3 n = x.density.size();
    return py::make_tuple(n.x, n.y, n.z);
  });
  f.def("max_speed", &ToonFields::maxSpeed, "Largest |face velocity| (m/s).");
}

void bindParticles(py::module_& m) {
  py::class_<ToonSession> c(
      m, "ToonParticles",
      "Cartoon-smoke particles driven frame by frame by a baked cache (cartoon_smoke §2.1-2.3): "
      "advected through the frame (Euler or midpoint substeps, at most cfl cells each), sampled "
      "from the frame-end fields, sized by the density ramp at most max_size_change per frame "
      "(a particle below death_density shrinks to 0 before it goes: no popping), emitted at the "
      "source and born (size 0) in empty cells denser than birth_density, at least birth_spacing "
      "stencil sizes from any particle, up to max_count. "
      "Same settings and seed give the same particles at any thread count; ids never repeat.");
  c.def(py::init([](const ToonParams& p, const std::array<int, 3>& res,
                    const std::array<float, 3>& origin, float cell, bool resample) {
          const GridFrame g = gridArg(res, origin, cell);
          return ToonSession{ToonParticles(p, g), ToonVolumeCache(g, resample)};
        }),
        py::arg("params"), py::arg("resolution"), py::arg("origin"), py::arg("cell_size"),
        py::arg("resample") = false,
        "On the bake's grid (resolution, world origin of cell (0,0,0)'s corner, cell size in m; "
        "resample: the volume frames are interpolated onto it, for a traced Mantaflow bake "
        "whose cells are not cubic). "
        "ValueError on bad params or grid.");
  c.def(
      "advance_frame",
      [](ToonSession& s, const ToonFields& before, const ToonFields& after, float dt,
         const py::object& cells, const py::object& points) {
        const ToonSources src = sourcesArg(cells, points);
        py::gil_scoped_release release;
        return s.particles.advanceFrame(before, after, dt, src);
      },
      py::arg("before"), py::arg("after"), py::arg("dt"), py::arg("source_cells") = py::none(),
      py::arg("source_points") = py::none(),
      "One frame of dt seconds from ToonFields `before` (frame start) to `after` (frame end); "
      "emission at source_cells (N, 3) int and source_points (N, 3) world. Returns the substeps. "
      "ValueError on bad input, RuntimeError when the speed needs > 4096 substeps; nothing "
      "changes when it raises.");
  c.def(
      "advance_frame_from_vdb",
      [](ToonSession& s, const py::object& before, const py::object& after, float dt,
         const py::object& cells, const py::object& points) {
        const std::string a = pathArg(before), b = pathArg(after);
        const ToonSources src = sourcesArg(cells, points);
        py::gil_scoped_release release;
        const ToonFields& fa = s.volumes.fields(a);
        const ToonFields& fb = s.volumes.fields(b);
        return s.particles.advanceFrame(fa, fb, dt, src);
      },
      py::arg("path_before"), py::arg("path_after"), py::arg("dt"),
      py::arg("source_cells") = py::none(), py::arg("source_points") = py::none(),
      "advance_frame() with the fields of two Plume volume_####.vdb files (the last two read "
      "are kept, so a frame-by-frame walk reads each file once). The first frame of a shot: "
      "pass the same path twice. RuntimeError naming a missing or foreign file.");
  c.def_property_readonly("count", [](const ToonSession& s) { return s.particles.count(); });
  c.def_property_readonly("frame", [](const ToonSession& s) { return s.particles.state().frame; },
                          "Frames advanced so far.");
  c.def_property_readonly("params", [](const ToonSession& s) { return s.particles.params(); });
  c.def(
      "snapshot", [](const ToonSession& s) { return stateResult(s.particles.state()); },
      "dict: frame, next_id, ids (N,) uint64 ascending, positions (N, 3) m, velocities (N, 3) "
      "m/s, density, temperature, size (m), target_size, color (ramp parameter in [0, 1]) (N,) "
      "float32, age (N,) int32 frames.");
  c.def(
      "billboards",
      [](const ToonSession& s, const DoubleC& matrix, bool perspective) {
        const ToonCamera cam = cameraArg(matrix, perspective);
        const ToonParticleState& st = s.particles.state();
        Billboards b;
        {
          py::gil_scoped_release release;
          b = computeBillboards(cam, st.positions, st.velocities, s.particles.params().stretchFactor);
        }
        return billboardsResult(b);
      },
      py::arg("camera_matrix"), py::arg("perspective") = true,
      "Figure 4 for the particles now, with params.stretch_factor: see toon_billboards().");
  c.def(
      "write",
      [](const ToonSession& s, const py::object& path) {
        withPath(path, [&](const std::string& p) { writeToonFile(p, s.particles.state()); });
      },
      py::arg("path"), "Writes the particles as a toon file (toon_####.bin), atomically.");
  c.def(
      "load",
      [](ToonSession& s, const py::object& path) {
        withPath(path, [&](const std::string& p) { s.particles.setState(readToonFile(p)); });
      },
      py::arg("path"),
      "Replaces the particles with a toon file's (resume a build from its last frame). "
      "RuntimeError on a corrupt file, ValueError if it holds more than max_count particles.");
}

void bindFunctions(py::module_& m) {
  m.def(
      "toon_billboards",
      [](const DoubleC& matrix, bool perspective, const py::object& positions,
         const py::object& velocities, float stretch) {
        const ToonCamera cam = cameraArg(matrix, perspective);
        const auto p = tripletsArg<glm::vec3, FloatC>(positions, "positions");
        const auto v = tripletsArg<glm::vec3, FloatC>(velocities, "velocities");
        Billboards b;
        {
          py::gil_scoped_release release;
          b = computeBillboards(cam, p, v, stretch);
        }
        return billboardsResult(b);
      },
      py::arg("camera_matrix"), py::arg("perspective"), py::arg("positions"),
      py::arg("velocities"), py::arg("stretch_factor"),
      "Stencil orientation and squash/stretch (cartoon_smoke Figure 4) for a camera "
      "(matrix_world 4x4, perspective or not): dict angle (N,) radians from the camera's +x "
      "toward +y of the velocity projected on the image plane, stretch (N,) = 1 + k |v_screen| "
      "(v_screen in m/s at the particle's depth), axis (N, 3) the stretch direction in world "
      "space.");
  m.def(
      "depth_differences",
      [](const FloatC& depth, float gamma, float dx, float dy, bool ignoreBackground, float far) {
        if (depth.ndim() != 2) throw py::value_error("depth must be a 2-D array (rows, columns)");
        DepthDifferenceParams p{gamma, dx, dy, ignoreBackground, far};
        p.validate();
        const int h = int(depth.shape(0)), w = int(depth.shape(1));
        py::array_t<std::uint8_t> out({py::ssize_t(h), py::ssize_t(w)});
        std::uint8_t* o = out.mutable_data();
        const float* z = depth.data();
        {
          py::gil_scoped_release release;
          depthDifferences(z, w, h, p, o);
        }
        return out;
      },
      py::arg("depth"), py::arg("gamma"), py::arg("dx") = 1.f, py::arg("dy") = 1.f,
      py::arg("ignore_background") = false,
      py::arg("far") = std::numeric_limits<float>::infinity(),
      "The depth-differences outline test of cartoon_smoke §2.2: uint8 (rows, columns), 1 where "
      "|z(i±1,j) - z(i,j)| / dx or |z(i,j±1) - z(i,j)| / dy exceeds gamma (neighbours outside "
      "the image skipped); with ignore_background, pixels with depth not < far (inf, NaN) are "
      "never outlined (the silhouette lies on the smoke side). ValueError on gamma < 0, dx or "
      "dy <= 0.");
  m.def("toon_file_name", &toonFileName, py::arg("frame"), "'toon_0007.bin' for frame 7.");
  m.def(
      "read_toon_file",
      [](const py::object& path) { return stateResult(withPath(path, readToonFile)); },
      py::arg("path"),
      "A toon file as ToonParticles.snapshot() returns it. RuntimeError naming the file when it "
      "is missing, truncated or corrupt.");
}

}  // namespace

void bindToon(py::module_& m) {
  bindParams(m);
  bindFields(m);
  bindParticles(m);
  bindFunctions(m);
}

}  // namespace plume::bindings
