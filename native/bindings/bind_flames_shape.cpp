/// \file bind_flames_shape.cpp
/// Structural flames, shape and render side ([Structural Flames] §4.4–4.5, §5): profiles,
/// the camera, the shaper (samples, noises, mapping, merging, incandescence, lights) and the
/// flame VDB. Flames are dicts: points (N, 3) base to tip, optional velocities (N, 3), ages (N,),
/// radius, intensity, temperature, id, source, separated. Conversions and docstrings only;
/// shaping and rasterization release the GIL.

#include "bindings/bindings.h"
#include "bindings/convert.h"

#include "flames/flame_raster.h"
#include "flames/flame_shape.h"

#include <pybind11/stl.h>

#include <cstring>

namespace py = pybind11;

namespace plume::bindings {
namespace {

ColorImage imageArg(const py::handle& o) {
  const FloatArrayC a = FloatArrayC::ensure(o);
  if (!a || a.ndim() != 3 || a.shape(2) != 3)
    throw py::value_error("color images must be float arrays of shape (height, width, 3), row 0 at the bottom");
  ColorImage image;
  image.height = int(a.shape(0));
  image.width = int(a.shape(1));
  image.rgb.assign(a.data(), a.data() + a.size());
  return image;
}

/// The particle arrays of a shape() result dict, for the rasterizer.
FlameParticles particlesArg(const py::dict& d) {
  FlameParticles p;
  auto vec3s = [&](const char* key, std::vector<glm::vec3>& out) {
    const FloatArrayC a = FloatArrayC::ensure(d[key]);
    if (!a || a.ndim() != 2 || a.shape(1) != 3) throw py::value_error(std::string(key) + " must have shape (N, 3)");
    out = pointsArg(a, key);
  };
  auto floats = [&](const char* key, std::vector<float>& out) {
    const FloatArrayC a = FloatArrayC::ensure(d[key]);
    if (!a || a.ndim() != 1) throw py::value_error(std::string(key) + " must have shape (N,)");
    out.assign(a.data(), a.data() + a.size());
  };
  vec3s("positions", p.positions);
  vec3s("velocities", p.velocities);
  vec3s("colors", p.colors);
  floats("density", p.density);
  floats("mass", p.mass);
  floats("power", p.power);
  const std::size_t n = p.positions.size();
  if (p.velocities.size() != n || p.colors.size() != n || p.density.size() != n || p.mass.size() != n ||
      p.power.size() != n)
    throw py::value_error("particle arrays must all have the same length");
  return p;
}

}  // namespace

void bindFlamesShape(py::module_& m) {
  py::class_<FlameProfile> profile(m, "FlameProfile",
                                   "Normalized flame profile r(s) (structural_flames §4.4, Figure 3).");
  profile.def_static("library", [](const std::string& name) { return FlameProfile::library(profileShapeFromName(name)); },
                     py::arg("name"), "'candle', 'torch' or 'campfire'; ValueError otherwise.");
  profile.def_static(
      "from_curve",
      [](const py::object& points) {
        const DoubleArrayC a = doubleRowsArg(points, 2, "points");
        std::vector<glm::dvec2> p;
        for (py::ssize_t k = 0; k < a.shape(0); ++k) p.push_back({a.at(k, 0), a.at(k, 1)});
        return FlameProfile::fromCurve(p);
      },
      py::arg("points"), "From (radius, height) points base to tip (a Blender curve); ValueError on bad curves.");
  profile.def("radius", &FlameProfile::radius, py::arg("s"), "r(s), max 1.");
  profile.def_property_readonly("aspect", &FlameProfile::aspect, "Height / widest radius.");

  py::class_<FlameCamera> camera(m, "FlameCamera", "Camera for sample counts (§5.3) and eq. 6's distance.");
  camera.def(py::init([](const py::object& position, double focal, double sensor, int width, int height) {
               FlameCamera c;
               c.position = dvec3Arg(position, "position");
               c.focalLength = focal;
               c.sensorWidth = sensor;
               c.width = width;
               c.height = height;
               c.validate();
               return c;
             }),
             py::arg("position"), py::arg("focal_length") = 50.0, py::arg("sensor_width") = 36.0,
             py::arg("width") = 1920, py::arg("height") = 1080, "focal_length, sensor_width in mm.");

  py::class_<FlameShaper> shaper(m, "FlameShaper",
                                 "Shape stage of structural flames: eq. 4 samples, flow noise, Figure 4 mapping, "
                                 "Kolmogorov noise, merging, eq. 5-6, lights.");
  shaper.def(
      py::init([](const std::vector<FlameProfile>& profiles, const py::object& images, std::uint64_t seed,
                  double falloff, double cutoff, double ppp, int minCount, int maxCount, int fixedCount,
                  double flowAmplitude, double flowScale, double flowFrequency, double flowRotation,
                  double kAmplitude, double kScale, const py::object& kDrift, double kFrequency, int kResolution,
                  double energyScale, double heat, double fuelArea, double width, bool merging, double temperature,
                  int threads, double coolingTime) {
        FlameShapeParams p;
        p.seed = seed;
        p.density.falloff = falloff;
        p.density.cutoff = cutoff;
        p.sampling.particlesPerPixel = ppp;
        p.sampling.minParticles = minCount;
        p.sampling.maxParticles = maxCount;
        p.sampling.fixedCount = fixedCount;
        p.flowNoise = {flowAmplitude, flowScale, flowFrequency, flowRotation};
        p.kolmogorov.amplitude = kAmplitude;
        p.kolmogorov.scale = kScale;
        p.kolmogorov.drift = dvec3Arg(kDrift, "kolmogorov_drift");
        p.kolmogorov.frequency = kFrequency;
        p.kolmogorov.resolution = kResolution;
        p.incandescence = {energyScale, heat, fuelArea};
        p.width = width;
        p.merging = merging;
        p.temperature = temperature;
        p.threads = threads;
        p.coolingTime = coolingTime;
        std::vector<ColorImage> list;
        if (!images.is_none())
          for (const py::handle& h : images) list.push_back(imageArg(h));
        py::gil_scoped_release release;
        return std::make_unique<FlameShaper>(profiles, p, std::move(list));
      }),
      py::arg("profiles"), py::arg("images") = py::none(), py::arg("seed") = 0, py::arg("falloff") = 0.5,
      py::arg("cutoff") = 2.0, py::arg("particles_per_pixel") = 10.0, py::arg("min_particles") = 64,
      py::arg("max_particles") = 100000, py::arg("fixed_count") = 0, py::arg("flow_noise_amplitude") = 0.15,
      py::arg("flow_noise_scale") = 0.8, py::arg("flow_noise_frequency") = 3.0, py::arg("flow_noise_rotation") = 0.5,
      py::arg("kolmogorov_amplitude") = 0.01, py::arg("kolmogorov_scale") = 0.5,
      py::arg("kolmogorov_drift") = py::make_tuple(0.0, 0.0, 0.5), py::arg("kolmogorov_frequency") = 0.5,
      py::arg("kolmogorov_resolution") = 32, py::arg("energy_scale") = 1.0, py::arg("heat_of_combustion") = 15.0e6,
      py::arg("fuel_area") = 0.0, py::arg("width") = 1.0, py::arg("merging") = true, py::arg("temperature") = 1500.0,
      py::arg("threads") = 0, py::arg("cooling_time") = 0.0,
      "profiles: flame f uses profiles[min(source, len-1)]; images: None, one, or one per profile, float "
      "(height, width, 3) row 0 at the bottom, on the profile's side view; a flame without one takes the "
      "blackbody colour of temperature x d (K); cooling_time: A (s), a separated piece's colour moves to the "
      "profile's tip as its gas ages (e^(-t_p / A); 0 off). ValueError on bad settings.");
  shaper.def(
      "set_obstacles",
      [](FlameShaper& s, const std::vector<std::shared_ptr<ObstacleSdf>>& obstacles) {
        auto set = std::make_shared<ObstacleSet>();
        for (const auto& o : obstacles) set->add(o);
        s.setObstacles(obstacles.empty() ? nullptr : std::move(set));
      },
      py::arg("obstacles"),
      "§6.1: particles whose final position is inside one of these obstacles (the ObstacleSdf objects "
      "given to FlameSystem.add_obstacle, shared, not copied) are dropped; [] keeps all.");
  shaper.def(
      "shape",
      [](const FlameShaper& s, const py::list& flames, double time, const FlameCamera& camera) {
        std::vector<Flame> list;
        for (std::size_t k = 0; k < flames.size(); ++k) list.push_back(flameArg(flames[k], k));
        FlameShapeFrame frame;
        {
          py::gil_scoped_release release;
          s.shape(list, time, camera, frame);
        }
        const FlameParticles& p = frame.particles;
        py::dict d;
        d["positions"] = rowsArray(p.positions);
        d["velocities"] = rowsArray(p.velocities);
        d["colors"] = rowsArray(p.colors);
        d["density"] = array1D(p.density);
        d["incandescence"] = array1D(p.incandescence);
        d["mass"] = array1D(p.mass);
        d["power"] = array1D(p.power);
        d["flame"] = array1D(p.flame);
        d["sampled"] = frame.sampled;
        d["energy"] = frame.energy;
        d["merged"] = frame.merged;
        d["obstructed"] = frame.obstructed;
        py::list lights;
        for (const FlameLight& l : frame.lights) {
          py::dict ld;
          ld["flame_id"] = l.flameId;
          ld["centre"] = vec3Tuple(l.centre);
          ld["radius"] = l.radius;
          ld["energy"] = l.energy;
          ld["color"] = vec3Tuple(l.color);
          lights.append(ld);
        }
        d["lights"] = lights;
        return d;
      },
      py::arg("flames"), py::arg("time"), py::arg("camera"),
      "dict: positions, velocities, colors (N, 3) float32; density (eq. 4), incandescence (eq. 6, W/m² at "
      "the camera), power (its share of eq. 5's E, W), mass (N,); "
      "flame (N,) input index; sampled, energy (eq. 5) per flame; merged; obstructed (§6.1); lights [dict(flame_id, centre, "
      "radius h/3, energy, color)].");

  m.def(
      "write_flames_vdb",
      [](const py::object& path, const py::dict& particles, float voxelSize, const py::object& origin,
         float temperatureScale, float lightUnit, float opacity, float blurReach, int frame, int threads) {
        FlameRasterParams r;
        r.blurReach = blurReach;
        r.emissionScale = lightUnit;
        r.opacity = opacity;
        r.voxelSize = voxelSize;
        r.origin = glm::vec3(dvec3Arg(origin, "origin"));
        r.temperatureScale = temperatureScale;
        r.threads = threads;
        r.validate();
        const FlameParticles p = particlesArg(particles);
        return withPath(path, [&](const std::string& file) {
          const FlameGrids grids = rasterizeFlames(p, r);
          writeFlameVdb(file, grids, frame);
          return std::size_t(grids.density->activeVoxelCount());
        });
      },
      py::arg("path"), py::arg("particles"), py::arg("voxel_size"), py::arg("origin") = py::make_tuple(0, 0, 0),
      py::arg("temperature_scale") = 1500.f, py::arg("light_unit") = 1.f, py::arg("opacity") = 1.f, py::arg("blur_reach") = 0.f,
      py::arg("frame") = 0, py::arg("threads") = 0,
      "Rasterizes a FlameShaper.shape() result into grids emission (W/m^3: light_unit x the particles' "
      "power), color, density (opacity x d^2, §5.3), temperature, flame, velocity (blur_reach > 0: "
      "4x coarser, extended blur_reach m past the particles for motion blur) and writes them "
      "atomically; returns the active voxel count of the density grid.");
}

}  // namespace plume::bindings
