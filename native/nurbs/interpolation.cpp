#include "nurbs/interpolation.h"

#include "nurbs/banded_lu.h"
#include "nurbs/basis.h"
#include "nurbs/knots.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace plume {
namespace {

/// The factorised collocation matrix A_ij = N_j(τ_i) of one direction.
BandedLu collocationMatrix(int pointCount, int order, bool endpoint) {
  const std::vector<float> knots = blenderKnots(pointCount, order, endpoint);
  const std::vector<double> tau = interpolationParameters(pointCount, order, endpoint);
  std::vector<BasisValues> rows(static_cast<std::size_t>(pointCount));
  int lower = 0, upper = 0;
  for (int i = 0; i < pointCount; ++i) {
    rows[std::size_t(i)] = basisFunctions(knots, pointCount, order, tau[std::size_t(i)]);
    const int first = rows[std::size_t(i)].first;
    lower = std::max(lower, i - first);
    upper = std::max(upper, first + order - 1 - i);
  }
  BandedLu lu(pointCount, lower, upper);
  for (int i = 0; i < pointCount; ++i) {
    const BasisValues& b = rows[std::size_t(i)];
    for (int r = 0; r < order; ++r) lu.set(i, b.first + r, b.values[std::size_t(r)]);
  }
  lu.factor();
  return lu;
}

void checkCount(const char* name, int n) {
  if (n < 1) {
    std::ostringstream s;
    s << name << " must be at least 1 (got " << n << ")";
    throw std::invalid_argument(s.str());
  }
}

}  // namespace

void interpolateCurve(std::vector<glm::dvec3>& values, int pointCount, int order, bool endpoint) {
  if (values.size() != std::size_t(pointCount))
    throw std::invalid_argument("interpolateCurve: values must hold point count points");
  const BandedLu lu = collocationMatrix(pointCount, order, endpoint);
  lu.solve(values);
}

NurbsSurface interpolateSurface(const std::vector<glm::vec3>& Q, int nu, int nv,
                                const SurfaceSpec& spec) {
  spec.validate();
  checkCount("nu (particles per streakline)", nu);
  checkCount("nv (streaklines)", nv);
  if (Q.size() != std::size_t(nu) * std::size_t(nv)) {
    std::ostringstream s;
    s << "points must hold nu * nv = " << std::size_t(nu) * std::size_t(nv) << " points (got "
      << Q.size() << ")";
    throw std::invalid_argument(s.str());
  }
  for (const glm::vec3& q : Q)
    if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z))
      throw std::invalid_argument("points must be finite");

  // A single data point in a direction becomes two equal control points (order 2): the smallest
  // net Blender draws, constant along that direction.
  NurbsSurface s;
  s.nu = std::max(nu, 2);
  s.nv = std::max(nv, 2);
  s.orderU = std::min(spec.orderU, s.nu);
  s.orderV = std::min(spec.orderV, s.nv);
  s.endpointU = spec.endpointU;
  s.endpointV = spec.endpointV;

  // Data on the (possibly padded) net, in double: grid[v * NU + u].
  const int NU = s.nu, NV = s.nv;
  std::vector<glm::dvec3> grid(std::size_t(NU) * std::size_t(NV));
  for (int v = 0; v < NV; ++v)
    for (int u = 0; u < NU; ++u)
      grid[std::size_t(v) * NU + u] = glm::dvec3(Q[std::size_t(std::min(v, nv - 1)) * nu + std::min(u, nu - 1)]);

  // Along u, one solve per streakline (the matrix is factorised once).
  const BandedLu luU = collocationMatrix(NU, s.orderU, s.endpointU);
  std::vector<glm::dvec3> line(static_cast<std::size_t>(NU));
  for (int v = 0; v < NV; ++v) {
    std::copy_n(grid.begin() + std::ptrdiff_t(v) * NU, NU, line.begin());
    luU.solve(line);
    std::copy_n(line.begin(), NU, grid.begin() + std::ptrdiff_t(v) * NU);
  }
  // Then along v, one solve per column of intermediate control points.
  const BandedLu luV = collocationMatrix(NV, s.orderV, s.endpointV);
  line.resize(std::size_t(NV));
  for (int u = 0; u < NU; ++u) {
    for (int v = 0; v < NV; ++v) line[std::size_t(v)] = grid[std::size_t(v) * NU + u];
    luV.solve(line);
    for (int v = 0; v < NV; ++v) grid[std::size_t(v) * NU + u] = line[std::size_t(v)];
  }

  s.controlPoints.resize(grid.size());
  for (std::size_t n = 0; n < grid.size(); ++n) s.controlPoints[n] = glm::vec4(glm::vec3(grid[n]), 1.f);
  return s;
}

SurfaceParameters particleParameters(const NurbsSurface& s) {
  return {interpolationParameters(s.nu, s.orderU, s.endpointU),
          interpolationParameters(s.nv, s.orderV, s.endpointV)};
}

}  // namespace plume
