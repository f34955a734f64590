/// \file bind_toon_particles.cpp
/// Toon smoke ([Cartoon Smoke]) for Python: ToonParticles driven by ToonFields or by Plume
/// volume frames, stencil billboards (Figure 4), the depth-differences reference filter (§2.2)
/// and the toon cache files. Conversions and docstrings only; frames, file reads and writes,
/// billboards and the filter release the GIL.

#include "bindings/bindings.h"
#include "bindings/convert.h"

#include "toon/toon_file.h"
#include "toon/toon_volume.h"
#include "toon/billboard.h"
#include "toon/depth_differences.h"
#include "toon/toon_particles.h"

#include <pybind11/stl.h>

#include <array>
#include <limits>

namespace py = pybind11;

namespace plume::bindings {
namespace {

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
  return ToonSources{tripletsArg<glm::ivec3, Int32ArrayC>(cells, "source_cells"),
                     tripletsArg<glm::vec3, FloatArrayC>(points, "source_points")};
}

py::dict stateResult(const ToonParticleState& s) {
  py::dict d;
  d["frame"] = s.frame;
  d["next_id"] = s.nextId;
  d["ids"] = array1D(s.ids);
  d["positions"] = rowsArray(s.positions);
  d["velocities"] = rowsArray(s.velocities);
  d["density"] = array1D(s.density);
  d["temperature"] = array1D(s.temperature);
  d["size"] = array1D(s.size);
  d["target_size"] = array1D(s.targetSize);
  d["color"] = array1D(s.color);
  d["age"] = array1D(s.age);
  return d;
}

ToonCamera cameraArg(const DoubleArrayC& m, bool perspective) {
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
  d["angle"] = array1D(b.angle);
  d["stretch"] = array1D(b.stretch);
  d["axis"] = rowsArray(b.axis);
  return d;
}

/// ToonParticles with the volume frames it last read (a frame-by-frame walk reads each once).
struct ToonSession {
  ToonParticles particles;
  ToonVolumeCache volumes;
};

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
          const GridFrame g = toonGrid(ivec3Of(res), vec3Of(origin), cell);
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
      [](const ToonSession& s, const DoubleArrayC& matrix, bool perspective) {
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
      [](const DoubleArrayC& matrix, bool perspective, const py::object& positions,
         const py::object& velocities, float stretch) {
        const ToonCamera cam = cameraArg(matrix, perspective);
        const auto p = tripletsArg<glm::vec3, FloatArrayC>(positions, "positions");
        const auto v = tripletsArg<glm::vec3, FloatArrayC>(velocities, "velocities");
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
      [](const FloatArrayC& depth, float gamma, float dx, float dy, bool ignoreBackground, float far) {
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

void bindToonParticles(py::module_& m) {
  bindParticles(m);
  bindFunctions(m);
}

}  // namespace plume::bindings
