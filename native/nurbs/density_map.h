#pragma once
/// \file density_map.h
/// The density (opacity) map of a streak surface ([Smoke Surfaces] §3.4, Figures 8 and 10):
/// the simulated density sampled on the surface at supersampling rates k_u, k_v between the
/// particles, with the solver's interpolation, as a float image in (u, v).

#include "core/grid3.h"
#include "core/sampling.h"
#include "nurbs/surface.h"

#include <glm/glm.hpp>

#include <functional>
#include <vector>

namespace plume {

/// Settings of the §3.4 supersampling. Field names are the Python names in snake_case.
struct DensityMapParams {
  int samplingU = 4;  ///< k_u: samples between consecutive particles along a streakline (Fig. 10: 4)
  int samplingV = 2;  ///< k_v: samples between consecutive streaklines (Fig. 10: 2)
  /// How the density grid is read between its samples: the solver's scheme (§3.4 "the same
  /// interpolation scheme").
  Interpolation interpolation = Interpolation::MonotonicCubic;
  glm::vec3 origin{0.f};  ///< world position of the grid's minimum corner (cell (0,0,0)'s corner)
  float cellSize = 1.f;   ///< Δx; cell (i,j,k)'s centre is origin + (i + 0.5, j + 0.5, k + 0.5) Δx

  /// Throws std::invalid_argument: sampling_u/v in [0, 64], cell_size in [1e-6, 1e6], finite origin.
  void validate() const;
};

/// A density map: width = (nu - 1)(k_u + 1) + 1 columns, height = (nv - 1)(k_v + 1) + 1 rows,
/// values row-major v then u (values[y * width + x]). Column x = a (k_u + 1) is particle a;
/// parametersU[x] / parametersV[y] are the surface parameters of each column / row.
struct DensityMap {
  int width = 0;
  int height = 0;
  std::vector<double> parametersU;
  std::vector<double> parametersV;
  std::vector<float> values;

  float at(int x, int y) const { return values[std::size_t(y) * std::size_t(width) + std::size_t(x)]; }
};

/// Parameters k samples apart between consecutive nodes: node a, then a + j/(k+1) of the way to
/// node a + 1 for j = 1..k (the §3.4 "points between the particles in UV coordinates").
std::vector<double> supersampleParameters(const std::vector<double>& nodes, int rate);

/// §3.4: samples `density` (a grid of the solver, sampled with params.interpolation) at the
/// surface points S(u, v) for the supersampled particle parameters (particleParameters() of an
/// interpolating surface). Points outside the grid's box [origin, origin + size·Δx] read 0:
/// no smoke is simulated there, as the tracer gives particles that left the domain density 0.
/// Rows run in parallel; the result does not depend on the thread count.
DensityMap densityMap(const NurbsSurface& surface, const ScalarGrid& density,
                      const DensityMapParams& params);

/// The same sampling (params.samplingU/V unused) at the parameters us × vs, e.g. the evenly
/// spaced ones of Blender's generated UVs (evenParameters()) for a fitted surface, whose
/// particles sit at chord-length parameters.
DensityMap densityMapAt(const NurbsSurface& surface, const ScalarGrid& density,
                        const DensityMapParams& params, const std::vector<double>& us,
                        const std::vector<double>& vs);

/// `count` evenly spaced parameters from start to end (Blender lays a SURFACE's generated UVs
/// out this way over the drawn domain: u = sample / (samples − 1)). count >= 2.
std::vector<double> evenParameters(double start, double end, int count);

/// Figure 8's reconstruction: the map read at surface parameters (u, v), linear between its
/// samples in each direction (bilinear), parameters clamped to the map.
float densityMapValue(const DensityMap& map, double u, double v);

/// Bilinear read of the image at fractional pixel coordinates (x, y), clamped to the image.
float densityImageValue(const std::vector<float>& image, int width, int height, double x, double y);

/// Root-mean-square and largest difference between a reconstruction and the field it samples.
struct DensityMapError {
  double rms = 0.0;
  double max = 0.0;
};

/// Figure 8 in one dimension: `field` on [0, 1] read at `particles` evenly spaced particles plus
/// `rate` samples between consecutive ones, linearly interpolated, compared with the field at
/// `evaluationSamples` evenly spaced points. The error falls as the rate grows.
DensityMapError densityMapError1D(const std::function<double(double)>& field, int particles,
                                  int rate, int evaluationSamples = 1001);

/// The same on a surface: densityMapValue() against the density sampled on the surface
/// (params.interpolation) at `evaluationRate` samples between particles in each direction.
DensityMapError densityMapError(const NurbsSurface& surface, const ScalarGrid& density,
                                const DensityMapParams& params, const DensityMap& map,
                                int evaluationRate = 32);

}  // namespace plume
