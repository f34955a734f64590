/// \file bind_toon.cpp
/// Toon smoke ([Cartoon Smoke]) settings and inputs for Python: ToonParams with its enums and
/// the fields of a frame, from NumPy arrays or a Plume volume frame (the particles, billboards,
/// outlines and toon files are in bind_toon_particles.cpp). Conversions and docstrings only;
/// file reads release the GIL.

#include "bindings/bindings.h"
#include "bindings/convert.h"

#include "toon/toon_volume.h"
#include "toon/toon_fields.h"
#include "toon/toon_params.h"

#include <pybind11/stl.h>

#include <array>

namespace py = pybind11;

namespace plume::bindings {
namespace {

/// An (nx, ny, nz) array indexed [i, j, k] into a grid of `n` cells (x fastest in memory).
void fieldArg(const py::handle& o, glm::ivec3 n, ScalarGrid& g, const std::string& name) {
  const FloatArrayF a = FloatArrayF::ensure(o);
  if (!a || a.ndim() != 3 || a.shape(0) != n.x || a.shape(1) != n.y || a.shape(2) != n.z)
    throw py::value_error(name + " must be a float array of shape (" + std::to_string(n.x) + ", " +
                          std::to_string(n.y) + ", " + std::to_string(n.z) + ")");
  g.resize(n);
  std::memcpy(g.data(), a.data(), g.count() * sizeof(float));
}

ToonFields fieldsArg(const py::handle& density, const py::sequence& velocity,
                     const py::object& temperature) {
  const FloatArrayF d = FloatArrayF::ensure(density);
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
        const GridFrame g = toonGrid(ivec3Of(res), vec3Of(origin), cell);
        return withPath(path, [&](const std::string& p) {
          return resample ? resampleToonFields(p, g) : readToonFields(p, g);
        });
      },
      py::arg("path"), py::arg("resolution"), py::arg("origin"), py::arg("cell_size"),
      py::arg("resample") = false,
      "Reads a Plume volume_####.vdb onto the bake's grid (RuntimeError naming the file when it "
      "is missing, unreadable or of another domain). resample: interpolate a volume whose "
      "voxels are not the grid's cells (a traced Mantaflow bake) onto the grid.");
  f.def_property_readonly("resolution", [](const ToonFields& x) { return vec3Tuple(x.density.size()); });
  f.def("max_speed", &ToonFields::maxSpeed, "Largest |face velocity| (m/s).");
}

}  // namespace

void bindToon(py::module_& m) {
  bindParams(m);
  bindFields(m);
  bindToonParticles(m);
}

}  // namespace plume::bindings
