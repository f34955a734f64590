#include "nurbs/surface_fit.h"

#include "core/parallel.h"
#include "nurbs/chord_parameters.h"
#include "nurbs/evaluation.h"
#include "nurbs/interpolation.h"
#include "nurbs/knots.h"
#include "nurbs/least_squares.h"
#include "nurbs/near_particles.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace plume {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void checkNet(const char* name, int n) {
  if (n < 2) {
    std::ostringstream s;
    s << name << " must be at least 2 control points (got " << n << ")";
    throw std::invalid_argument(s.str());
  }
}

KnotDomain drawnDomain(int count, int order) {
  return blenderDomain(blenderKnots(count, order, true), count, order);
}

}  // namespace

/// The slot each slot's control point interpolates in slotsInterpolated() mode: the slot itself
/// when its particle is kept, else the nearest kept slot of the line (the older one on a tie):
/// particles not yet emitted take the youngest kept, those past an open side the oldest kept.
static std::vector<int> nearestKeptSlots(const StreakGrid& g, int b) {
  std::vector<int> slot(std::size_t(g.particles), -1);
  int last = -1;
  for (int a = 0; a < g.particles; ++a) {  // forward: the nearest kept at or before a
    if (g.kept(b, a)) last = a;
    slot[std::size_t(a)] = last;
  }
  last = -1;
  for (int a = g.particles - 1; a >= 0; --a) {  // backward: a nearer kept one after a wins
    if (g.kept(b, a)) last = a;
    const int before = slot[std::size_t(a)];
    if (last >= 0 && (before < 0 || last - a < a - before)) slot[std::size_t(a)] = last;
  }
  return slot;
}

LineCurves fitLines(const StreakGrid& g, int nu, const SurfaceFitParams& params) {
  params.validate();
  g.validate();
  checkNet("nu", nu);
  LineCurves c;
  c.nu = nu;
  c.order = std::min(params.orderU, nu);
  for (int b = 0; b < g.lines; ++b)
    for (int a = 0; a < g.particles; ++a)
      if (g.kept(b, a)) {
        c.lines.push_back(b);
        break;
      }
  c.controlPoints.resize(c.lines.size() * std::size_t(nu));
  c.paramsU.assign(std::size_t(g.lines) * std::size_t(g.particles), kNaN);
  c.quality.resize(c.lines.size());
  const KnotDomain dom = drawnDomain(nu, c.order);
  // One control point per slot at a low order: every line interpolated at the same Greville
  // abscissae (Schoenberg-Whitney holds there, so no penalty is needed), one factorisation.
  // The particle net uses the same slots and Greville abscissae, without solving for the
  // control points: the fitter only evaluates the curve there.
  const bool onParticles = particleNetU(g, nu, params);
  const bool slots = onParticles || slotsInterpolated(g, nu, params);
  std::unique_ptr<CurveFitter> slotFit;
  if (slots) slotFit = std::make_unique<CurveFitter>(interpolationParameters(nu, c.order, true),
                                                     nu, c.order, true, /*smoothing=*/0.0);
  parallelFor(0, int(c.lines.size()), [&](int r) {
    const int b = c.lines[std::size_t(r)];
    std::vector<int> kept;     // the kept particles, in slot order
    std::vector<int> rowOf;    // the fitter's data row of each of them
    std::vector<glm::dvec3> data;
    std::unique_ptr<CurveFitter> own;
    if (slots) {
      const std::vector<int> from = nearestKeptSlots(g, b);
      for (int a = 0; a < g.particles; ++a) {
        data.emplace_back(g.at(b, from[std::size_t(a)]));
        if (from[std::size_t(a)] == a) {
          kept.push_back(a);
          rowOf.push_back(a);
        }
      }
    } else {
      std::vector<glm::vec3> pts;
      for (int a = 0; a < g.particles; ++a)
        if (g.kept(b, a)) {
          kept.push_back(a);
          rowOf.push_back(int(pts.size()));
          pts.push_back(g.at(b, a));
          data.emplace_back(g.at(b, a));
        }
      const std::vector<double> t = mapParameters(
          averagedChordParameters({pts.data(), int(pts.size()), 1, 1, 0}, params.exponentU),
          dom.start, dom.end);
      own = std::make_unique<CurveFitter>(t, nu, c.order, true, params.smoothing);
    }
    const CurveFitter& fit = slots ? *slotFit : *own;
    glm::dvec3* row = c.controlPoints.data() + std::size_t(r) * std::size_t(nu);
    if (onParticles)
      std::copy(data.begin(), data.end(), row);
    else
      fit.fit(data.data(), 1, row, 1);
    CurveFitQuality& q = c.quality[std::size_t(r)];
    for (std::size_t i = 0; i < kept.size(); ++i) {
      const std::size_t k = std::size_t(rowOf[i]);
      c.paramsU[g.index(b, kept[i])] = fit.parameter(k);
      q.maxResidual = std::max(q.maxResidual, glm::length(fit.point(k, row, 1) - data[k]));
    }
    q.netDeviation = fit.netDeviation(row, 1);
  });
  return c;
}

bool particleNetU(const StreakGrid& g, int nu, const SurfaceFitParams& params) {
  return params.particleNetU && nu == g.particles && nu >= 2;
}

bool slotsInterpolated(const StreakGrid& g, int nu, const SurfaceFitParams& params) {
  return !params.particleNetU && nu == g.particles && nu >= 2 && std::min(params.orderU, nu) <= 3;
}

NearParticles keptParticles(const StreakGrid& g) {
  std::vector<glm::vec3> pts;
  glm::vec3 lo(0.f), hi(0.f);
  for (int b = 0; b < g.lines; ++b)
    for (int a = 0; a < g.particles; ++a)
      if (g.kept(b, a)) {
        lo = pts.empty() ? g.at(b, a) : glm::min(lo, g.at(b, a));
        hi = pts.empty() ? g.at(b, a) : glm::max(hi, g.at(b, a));
        pts.push_back(g.at(b, a));
      }
  // Buckets of about four particles were the particles to fill their box (they fill less of
  // it, sheets and lines, so more sit in the buckets they occupy), and no more than 256 across.
  const glm::dvec3 box = glm::max(glm::dvec3(hi - lo), glm::dvec3(1e-6));
  const double extent = std::max({box.x, box.y, box.z});
  const double filled = std::cbrt(box.x * box.y * box.z * 4.0 / double(pts.size()));
  return NearParticles(pts, std::max(filled, extent / 256.0));
}

void SurfaceFitParams::validate() const {
  for (int order : {orderU, orderV})
    if (order < kMinBlenderOrder || order > kMaxBlenderOrder) {
      std::ostringstream s;
      s << "order_u and order_v must be in [" << kMinBlenderOrder << ", " << kMaxBlenderOrder
        << "] (got " << orderU << ", " << orderV << ")";
      throw std::invalid_argument(s.str());
    }
  for (double x : {smoothing, exponentU, exponentV})
    if (!(x >= 0.0 && x <= 1.0)) {
      std::ostringstream s;
      s << "smoothing, exponent_u and exponent_v must be in [0, 1] (got " << smoothing << ", "
        << exponentU << ", " << exponentV << ")";
      throw std::invalid_argument(s.str());
    }
}

void StreakGrid::validate() const {
  if (points == nullptr || keep == nullptr || lines < 1 || particles < 1) {
    std::ostringstream s;
    s << "streak grid: need points, keep flags and lines, particles >= 1 (got lines = " << lines
      << ", particles = " << particles << ")";
    throw std::invalid_argument(s.str());
  }
  bool any = false;
  for (int b = 0; b < lines; ++b)
    for (int a = 0; a < particles; ++a) {
      if (!kept(b, a)) continue;
      any = true;
      const glm::vec3& q = at(b, a);
      if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z))
        throw std::invalid_argument("streak grid: particle positions must be finite");
    }
  if (!any) throw std::invalid_argument("streak grid: no particle is kept for the fit");
}

SurfaceFit fitSurface(const StreakGrid& g, int nu, int nv, const SurfaceFitParams& params) {
  return fitAcross(g, fitLines(g, nu, params), nv, params);
}

SurfaceFit fitAcross(const StreakGrid& g, const LineCurves& curves, int nv,
                     const SurfaceFitParams& params) {
  params.validate();
  g.validate();
  checkNet("nv", nv);
  if (curves.lines.empty() || curves.paramsU.size() != g.index(g.lines, 0))
    throw std::invalid_argument("fitAcross: the line curves are not of this streak grid");
  const int nu = curves.nu;
  SurfaceFit fit;
  NurbsSurface& s = fit.surface;
  s.nu = nu;
  s.nv = nv;
  s.orderU = curves.order;
  s.orderV = std::min(params.orderV, nv);
  s.endpointU = s.endpointV = true;
  fit.paramsU = curves.paramsU;

  // v: as many lines as control points -> interpolation at interpolationParameters() (they
  // satisfy Schoenberg-Whitney on Blender's knots, which chord lengths of unevenly spaced lines
  // may not); fewer control points -> the lines' control polygons at averaged chord length
  // (coincident lines merged), penalised least squares.
  const int rows = int(curves.lines.size());
  const bool interpolate = rows == nv;
  const bool onLines = interpolate && params.particleNetV;
  std::vector<double> tv;
  if (interpolate) {
    tv = interpolationParameters(nv, s.orderV, true);
  } else {
    std::vector<glm::vec3> polygons(curves.controlPoints.size());
    for (std::size_t n = 0; n < polygons.size(); ++n)
      polygons[n] = glm::vec3(curves.controlPoints[n]);
    const KnotDomain dom = drawnDomain(nv, s.orderV);
    tv = mapParameters(averagedChordParameters({polygons.data(), rows, nu, nu, 1}, params.exponentV),
                       dom.start, dom.end);
  }
  fit.paramsV.assign(std::size_t(g.lines), kNaN);
  for (int r = 0; r < rows; ++r)
    fit.paramsV[std::size_t(curves.lines[std::size_t(r)])] = tv[std::size_t(r)];

  // Step 2: one fit across the lines per column u of their control points.
  const CurveFitter fv(tv, nv, s.orderV, true, interpolate ? 0.0 : params.smoothing);
  std::vector<glm::dvec3> net(std::size_t(nu) * std::size_t(nv));
  if (onLines)  // the particle net across: the lines' curves are the rows of the net
    net = curves.controlPoints;
  else
    parallelFor(0, nu, [&](int u) { fv.fit(curves.controlPoints.data() + u, nu, net.data() + u, nu); });
  s.controlPoints.resize(net.size());
  for (std::size_t n = 0; n < net.size(); ++n) s.controlPoints[n] = glm::vec4(glm::vec3(net[n]), 1.f);

  // Residuals at the particles' own parameters, on the float control points Blender gets.
  const SurfaceKnots k = surfaceKnots(s);
  std::vector<double> worst(std::size_t(rows), 0.0);
  parallelFor(0, rows, [&](int r) {
    const int b = curves.lines[std::size_t(r)];
    for (int a = 0; a < g.particles; ++a) {
      if (!g.kept(b, a)) continue;
      const glm::vec3 p = surfacePoint(s, k, fit.paramsU[g.index(b, a)], fit.paramsV[std::size_t(b)]);
      const double d = glm::length(glm::dvec3(p) - glm::dvec3(g.at(b, a)));
      worst[std::size_t(r)] = std::max(worst[std::size_t(r)], d);
    }
  });
  fit.maxResidual = *std::max_element(worst.begin(), worst.end());
  const std::vector<glm::vec3> at = surfaceGrid(s, grevilleAbscissae(k.u, nu, s.orderU),
                                                grevilleAbscissae(k.v, nv, s.orderV));
  for (std::size_t n = 0; n < at.size(); ++n)
    fit.netDeviation =
        std::max(fit.netDeviation, double(glm::length(glm::vec3(s.controlPoints[n]) - at[n])));
  return fit;
}

CurveFitQuality curveFitQuality(const StreakGrid& g, int nu, const SurfaceFitParams& params,
                                const NearParticles* near) {
  const LineCurves curves = fitLines(g, nu, params);
  CurveFitQuality worst;
  for (const CurveFitQuality& q : curves.quality) {
    worst.maxResidual = std::max(worst.maxResidual, q.maxResidual);
    worst.netDeviation = std::max(worst.netDeviation, q.netDeviation);
  }
  if (near != nullptr)
    for (const glm::dvec3& p : curves.controlPoints)
      worst.netToParticles = std::max(worst.netToParticles, near->nearest(glm::vec3(p)));
  return worst;
}

double netToParticles(const NurbsSurface& surface, const StreakGrid& g) {
  g.validate();
  return netToParticles(surface, keptParticles(g));
}

double netToParticles(const NurbsSurface& surface, const NearParticles& near) {
  std::vector<double> d(surface.controlPoints.size(), 0.0);
  parallelFor(0, int(d.size()), [&](int n) {
    d[std::size_t(n)] = near.nearest(glm::vec3(surface.controlPoints[std::size_t(n)]));
  });
  return d.empty() ? 0.0 : *std::max_element(d.begin(), d.end());
}

}  // namespace plume
