#include "nurbs/density_map.h"

#include "core/parallel.h"
#include "nurbs/evaluation.h"
#include "nurbs/interpolation.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace plume {
namespace {

constexpr int kMaxSampling = 64;

void checkRate(const char* name, int rate) {
  if (rate < 0 || rate > kMaxSampling) {
    std::ostringstream s;
    s << name << " must be in [0, " << kMaxSampling << "] (got " << rate << ")";
    throw std::invalid_argument(s.str());
  }
}

/// Fractional index of t in the increasing samples `p` (clamped): i + (t - p_i)/(p_{i+1} - p_i).
double fractionalIndex(const std::vector<double>& p, double t) {
  if (p.size() < 2 || t <= p.front()) return 0.0;
  if (t >= p.back()) return double(p.size() - 1);
  const std::size_t i = std::size_t(std::upper_bound(p.begin(), p.end(), t) - p.begin()) - 1;
  const double span = p[i + 1] - p[i];
  return double(i) + (span > 0.0 ? (t - p[i]) / span : 0.0);
}

float sampleWorld(const ScalarGrid& density, const DensityMapParams& params, glm::vec3 world) {
  // Cell coordinates: the grid's box is [0, n] on each axis.
  const glm::vec3 c = (world - params.origin) / params.cellSize;
  const glm::vec3 n(density.size());
  // Outside the box no smoke is simulated (the tracer sets a particle's density to 0 once it
  // crosses a side, tracers/domain_sides.h): the sampler would repeat the edge cells instead.
  if (c.x < 0.f || c.y < 0.f || c.z < 0.f || c.x > n.x || c.y > n.y || c.z > n.z) return 0.f;
  // Index space of core/sampling.h: sample (i,j,k) sits at the cell centre.
  return sample(density, c - glm::vec3(0.5f), params.interpolation);
}

void checkGrid(const ScalarGrid& density) {
  const glm::ivec3 n = density.size();
  if (n.x < 1 || n.y < 1 || n.z < 1 || density.count() == 0)
    throw std::invalid_argument("density grid must not be empty");
}

}  // namespace

void DensityMapParams::validate() const {
  checkRate("sampling_u", samplingU);
  checkRate("sampling_v", samplingV);
  if (!std::isfinite(cellSize) || cellSize < 1e-6f || cellSize > 1e6f) {
    std::ostringstream s;
    s << "cell_size must be in [1e-06, 1e+06] (got " << cellSize << ")";
    throw std::invalid_argument(s.str());
  }
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(origin[a])) throw std::invalid_argument("origin must be finite");
}

std::vector<double> supersampleParameters(const std::vector<double>& nodes, int rate) {
  checkRate("sampling rate", rate);
  std::vector<double> out;
  if (nodes.empty()) return out;
  out.reserve((nodes.size() - 1) * std::size_t(rate + 1) + 1);
  for (std::size_t a = 0; a + 1 < nodes.size(); ++a)
    for (int j = 0; j <= rate; ++j)
      out.push_back(nodes[a] + (nodes[a + 1] - nodes[a]) * double(j) / double(rate + 1));
  out.push_back(nodes.back());
  return out;
}

DensityMap densityMap(const NurbsSurface& surface, const ScalarGrid& density,
                      const DensityMapParams& params) {
  params.validate();
  surface.validate();
  const SurfaceParameters particles = particleParameters(surface);
  return densityMapAt(surface, density, params, supersampleParameters(particles.u, params.samplingU),
                      supersampleParameters(particles.v, params.samplingV));
}

std::vector<double> evenParameters(double start, double end, int count) {
  if (count < 2 || !std::isfinite(start) || !std::isfinite(end))
    throw std::invalid_argument("even parameters need count >= 2 and a finite interval");
  std::vector<double> t(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i)
    t[std::size_t(i)] = start + (end - start) * double(i) / double(count - 1);
  t.back() = end;
  return t;
}

DensityMap densityMapAt(const NurbsSurface& surface, const ScalarGrid& density,
                        const DensityMapParams& params, const std::vector<double>& us,
                        const std::vector<double>& vs) {
  params.validate();
  surface.validate();
  checkGrid(density);
  if (us.empty() || vs.empty())
    throw std::invalid_argument("density map needs parameters in u and v");
  for (const std::vector<double>* t : {&us, &vs})
    for (std::size_t i = 0; i < t->size(); ++i)
      if (!std::isfinite((*t)[i]) || (i > 0 && (*t)[i] < (*t)[i - 1]))
        throw std::invalid_argument("density map parameters must be finite and increasing");
  DensityMap map;
  map.parametersU = us;
  map.parametersV = vs;
  map.width = int(map.parametersU.size());
  map.height = int(map.parametersV.size());
  const std::vector<glm::vec3> points = surfaceGrid(surface, map.parametersU, map.parametersV);
  map.values.resize(points.size());
  parallelFor(0, map.height, [&](int y) {
    for (int x = 0; x < map.width; ++x) {
      const std::size_t n = std::size_t(y) * std::size_t(map.width) + std::size_t(x);
      map.values[n] = sampleWorld(density, params, points[n]);
    }
  });
  return map;
}

float densityImageValue(const std::vector<float>& image, int width, int height, double x, double y) {
  if (width < 1 || height < 1 || image.size() != std::size_t(width) * std::size_t(height))
    throw std::invalid_argument("density image must hold width * height values");
  x = std::clamp(x, 0.0, double(width - 1));
  y = std::clamp(y, 0.0, double(height - 1));
  const int x0 = std::min(int(x), width - 1), y0 = std::min(int(y), height - 1);
  const int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
  const double fx = x - x0, fy = y - y0;
  auto at = [&](int i, int j) { return double(image[std::size_t(j) * std::size_t(width) + std::size_t(i)]); };
  const double bottom = at(x0, y0) + fx * (at(x1, y0) - at(x0, y0));
  const double top = at(x0, y1) + fx * (at(x1, y1) - at(x0, y1));
  return float(bottom + fy * (top - bottom));
}

float densityMapValue(const DensityMap& map, double u, double v) {
  return densityImageValue(map.values, map.width, map.height, fractionalIndex(map.parametersU, u),
                           fractionalIndex(map.parametersV, v));
}

DensityMapError densityMapError1D(const std::function<double(double)>& field, int particles,
                                  int rate, int evaluationSamples) {
  if (particles < 2) throw std::invalid_argument("particles must be at least 2");
  checkRate("sampling rate", rate);
  if (evaluationSamples < 2) throw std::invalid_argument("evaluation samples must be at least 2");
  std::vector<double> nodes(static_cast<std::size_t>(particles));
  for (int a = 0; a < particles; ++a) nodes[std::size_t(a)] = double(a) / double(particles - 1);
  const std::vector<double> t = supersampleParameters(nodes, rate);
  std::vector<double> f(t.size());
  for (std::size_t n = 0; n < t.size(); ++n) f[n] = field(t[n]);
  DensityMapError e;
  double sum = 0.0;
  for (int s = 0; s < evaluationSamples; ++s) {
    const double x = double(s) / double(evaluationSamples - 1);
    const double g = fractionalIndex(t, x);
    const std::size_t i = std::min(std::size_t(g), t.size() - 2);
    const double approx = f[i] + (g - double(i)) * (f[i + 1] - f[i]);
    const double d = std::abs(approx - field(x));
    sum += d * d;
    e.max = std::max(e.max, d);
  }
  e.rms = std::sqrt(sum / evaluationSamples);
  return e;
}

DensityMapError densityMapError(const NurbsSurface& surface, const ScalarGrid& density,
                                const DensityMapParams& params, const DensityMap& map,
                                int evaluationRate) {
  params.validate();
  checkGrid(density);
  checkRate("evaluation rate", evaluationRate);
  const SurfaceParameters particles = particleParameters(surface);
  const std::vector<double> us = supersampleParameters(particles.u, evaluationRate);
  const std::vector<double> vs = supersampleParameters(particles.v, evaluationRate);
  const std::vector<glm::vec3> points = surfaceGrid(surface, us, vs);
  // Per-row partial sums added in row order: deterministic for any thread count.
  std::vector<double> rowSum(vs.size(), 0.0), rowMax(vs.size(), 0.0);
  parallelFor(0, int(vs.size()), [&](int b) {
    for (std::size_t a = 0; a < us.size(); ++a) {
      const double truth = sampleWorld(density, params, points[std::size_t(b) * us.size() + a]);
      const double d = std::abs(double(densityMapValue(map, us[a], vs[std::size_t(b)])) - truth);
      rowSum[std::size_t(b)] += d * d;
      rowMax[std::size_t(b)] = std::max(rowMax[std::size_t(b)], d);
    }
  });
  DensityMapError e;
  double sum = 0.0;
  for (std::size_t b = 0; b < vs.size(); ++b) {
    sum += rowSum[b];
    e.max = std::max(e.max, rowMax[b]);
  }
  e.rms = std::sqrt(sum / double(us.size() * vs.size()));
  return e;
}

}  // namespace plume
