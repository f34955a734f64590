/// \file bind_solver_params.cpp
/// The settings of the smoke/fire solver for Python: the Trace enum, SmokeParams and
/// SourceSettings (SmokeSolver itself is in bind_solver.cpp). Conversions and docstrings only.

#include "bindings/bindings.h"
#include "bindings/convert.h"

#include "solver/smoke_params.h"
#include "solver/smoke_solver.h"

#include <pybind11/stl.h>

#include <limits>
#include <sstream>

namespace py = pybind11;

namespace plume::bindings {
namespace {

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
  c.def_static(
      "ranges",
      [] {
        py::dict d;
        for (const SettingRange& r : smokeSettingRanges()) d[r.name] = py::make_tuple(r.lo, r.hi);
        return d;
      },
      "{setting: (lo, hi)}: the accepted range of every bounded numeric setting (resolution per "
      "axis), the one definition validate() checks and the add-on's properties read.");
  c.def("__copy__", [](const SmokeParams& p) { return SmokeParams(p); });
  c.def("__deepcopy__", [](const SmokeParams& p, py::dict) { return SmokeParams(p); });

  c.def_property(
      "resolution",
      [](const SmokeParams& p) { return vec3Tuple(p.resolution); },
      [](SmokeParams& p, const py::object& v) {
        // Beyond an int: refused here, in validate()'s words; within it, validate() checks.
        const SettingRange& r = smokeSettingRange("resolution");
        const std::string range = "in [" + std::to_string(int(r.lo)) + ", " +
                                  std::to_string(int(r.hi)) + "] cells per axis";
        p.resolution = ivec3Arg(v, "resolution", std::numeric_limits<int>::min(),
                                std::numeric_limits<int>::max(), range.c_str());
      },
      "Cells per axis (nx, ny, nz).");
  c.def_readwrite("cell_size", &SmokeParams::cellSize, "Δx, metres.");
  c.def_property(
      "origin", [](const SmokeParams& p) { return vec3Tuple(p.origin); },
      [](SmokeParams& p, const py::object& v) { p.origin = vec3Arg(v, "origin", Vec3Form::Sequence); },
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
  field(c, "adaptive_domain", &SmokeParams::adaptiveDomain,
        "Step only the box around the smoke (Mantaflow's use_adaptive_domain); off by default.");
  field(c, "adaptive_margin", &SmokeParams::adaptiveMargin,
        "Cells of air kept around the smoke in the adaptive box (Mantaflow's adapt_margin).");
  field(c, "adaptive_threshold", &SmokeParams::adaptiveThreshold,
        "ρ, |T - T_amb|, F or S above which a cell counts as smoke (Mantaflow's adapt_threshold).");
  field(c, "frame_dt", &SmokeParams::frameDt, "Seconds per frame (1/fps × time scale).");
  field(c, "substeps", &SmokeParams::substeps, "Minimum steps per frame.");
  field(c, "use_cfl", &SmokeParams::useCfl, "Add steps so no cell moves more than `cfl` cells.");
  field(c, "cfl", &SmokeParams::cfl, "CFL number of the adaptive steps.");
  field(c, "advection", &SmokeParams::advection,
        "Advection.SEMI_LAGRANGIAN, Advection.BFECC or Advection.MACCORMACK.");
  field(c, "interpolation", &SmokeParams::interpolation,
        "Interpolation.LINEAR or Interpolation.MONOTONIC_CUBIC (Fedkiw 2001 eq. 12-13).");
  field(c, "linear_velocity", &SmokeParams::linearVelocity,
        "Carry the velocity with trilinear samples whatever `interpolation` is (a BFECC step "
        "about 2x cheaper; other small-scale motion). On by default.");
  field(c, "trace", &SmokeParams::trace,
        "Trace.MIDPOINT (RK2, the default) or Trace.EULER (first order, grid-point velocity).");
  field(c, "conserve_mass", &SmokeParams::conserveMass,
        "Restore the total smoke (and heat, T - T_amb) after each advection, less what left "
        "through open sides.");
  c.def_property(
      "gravity", [](const SmokeParams& p) { return vec3Tuple(p.gravity); },
      [](SmokeParams& p, const py::object& v) { p.gravity = vec3Arg(v, "gravity", Vec3Form::Sequence); },
      "g, m/s²; buoyancy acts against it.");
  field(c, "alpha", &SmokeParams::alpha, "α: buoyancy from density (Fedkiw 2001 eq. 8).");
  field(c, "beta", &SmokeParams::beta, "β: buoyancy from heat, f = -g (α ρ + β (T - T_amb)).");
  field(c, "ambient_temperature", &SmokeParams::ambientTemperature, "T_amb (T_0 of the fire paper).");
  c.def_property(
      "wind", [](const SmokeParams& p) { return vec3Tuple(p.wind); },
      [](SmokeParams& p, const py::object& v) { p.wind = vec3Arg(v, "wind", Vec3Form::Sequence); },
      "Wind velocity u_wind the air is pulled towards, m/s.");
  field(c, "wind_strength", &SmokeParams::windStrength, "k_w: f_wind = k_w (u_wind - u), 1/s.");
  field(c, "vorticity", &SmokeParams::vorticity, "ε: vorticity confinement (Fedkiw 2001 eq. 11).");
  field(c, "density_dissipation", &SmokeParams::densityDissipation, "Fraction of ρ lost per second.");
  field(c, "turbulence", &SmokeParams::turbulence, "A: strength of the turbulence force, m/s².");
  field(c, "turbulence_scale", &SmokeParams::turbulenceScale, "λ: size of the turbulence's swirls, m.");
  field(c, "turbulence_rate", &SmokeParams::turbulenceRate, "Turbulence pattern renewals per second.");
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
  field(c, "flame_vorticity", &SmokeParams::flameVorticity,
        "ε_f: vorticity confinement added where fuel burns, ε + ε_f min(F, 1).");
  field(c, "seed", &SmokeParams::seed, "Seed of every random choice.");
  field(c, "threads", &SmokeParams::threads, "Worker threads; 0 = all cores.");
  c.def("validate", &SmokeParams::validate,
        "Raises ValueError naming the first bad setting and its accepted range.");
  c.def("size", [](const SmokeParams& p) { return vec3Tuple(p.size()); },
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
      "velocity", [](const SourceSettings& s) { return vec3Tuple(s.velocity); },
      [](SourceSettings& s, const py::object& v) { s.velocity = vec3Arg(v, "velocity", Vec3Form::Sequence); },
      "Initial velocity, m/s (smoke_surfaces §3.2).");
  c.def_readwrite("motion_factor", &SourceSettings::motionFactor,
                  "Share of the source object's own motion added to its velocity.");
  c.def_property(
      "fuel_noise", [](const SourceSettings& s) { return s.fuelNoise.amount; },
      [](SourceSettings& s, float v) { s.fuelNoise.amount = v; },
      "Flicker a in [0, 1]: share of the fuel its patches may take away.");
  c.def_property(
      "fuel_noise_scale", [](const SourceSettings& s) { return s.fuelNoise.scale; },
      [](SourceSettings& s, float v) { s.fuelNoise.scale = v; }, "Size λ of the noise's patches, m.");
  c.def_property(
      "fuel_noise_rate", [](const SourceSettings& s) { return s.fuelNoise.rate; },
      [](SourceSettings& s, float v) { s.fuelNoise.rate = v; },
      "Patches renewed per second (the flicker's speed).");
  c.def_property(
      "smoke_noise", [](const SourceSettings& s) { return s.smokeNoise.amount; },
      [](SourceSettings& s, float v) { s.smokeNoise.amount = v; },
      "Breakup a in [0, 1]: share of the smoke and heat its patches may take away.");
  c.def_property(
      "smoke_noise_scale", [](const SourceSettings& s) { return s.smokeNoise.scale; },
      [](SourceSettings& s, float v) { s.smokeNoise.scale = v; }, "Size λ of the breakup's patches, m.");
  c.def_property(
      "smoke_noise_rate", [](const SourceSettings& s) { return s.smokeNoise.rate; },
      [](SourceSettings& s, float v) { s.smokeNoise.rate = v; },
      "Breakup patches renewed per second.");
  c.def("validate", &SourceSettings::validate, "Raises ValueError naming a bad setting.");
}

}  // namespace

void bindSolverParams(py::module_& m) {
  bindParams(m);
  bindSourceSettings(m);
}

}  // namespace plume::bindings
