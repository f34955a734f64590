#include "nurbs/shot_fit.h"

#include "core/parallel.h"
#include "nurbs/knots.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>
#include <stdexcept>

namespace plume {
namespace {

void checkFrames(const std::vector<StreakGrid>& frames) {
  if (frames.empty()) throw std::invalid_argument("a shot needs at least one frame");
  for (const StreakGrid& g : frames) {
    g.validate();
    if (g.particles != frames.front().particles || g.lines != frames.front().lines)
      throw std::invalid_argument("every frame of a shot needs the same particles and lines");
  }
}

/// True when f holds on every frame (each frame on its own task; the answer is order-free).
bool everyFrame(const std::vector<StreakGrid>& frames,
                const std::function<bool(const StreakGrid&)>& f) {
  std::vector<char> ok(frames.size(), 0);
  parallelFor(0, int(frames.size()), [&](int n) { ok[std::size_t(n)] = f(frames[std::size_t(n)]); });
  return std::all_of(ok.begin(), ok.end(), [](char c) { return c != 0; });
}

/// Smallest n in [lo, hi] where good(n) holds, assuming it keeps holding as n grows
/// (bisection; the answer always satisfies it unless even hi does not, then it is hi).
int smallestCount(int lo, int hi, const std::function<bool(int)>& good) {
  if (good(lo)) return lo;
  while (hi - lo > 1) {
    const int mid = lo + (hi - lo) / 2;
    if (good(mid))
      hi = mid;
    else
      lo = mid;
  }
  return hi;
}

}  // namespace

void ShotFitParams::validate() const {
  fit.validate();
  if (!std::isfinite(tolerance) || !(tolerance > 0.0) || !std::isfinite(netTolerance) ||
      !(netTolerance > 0.0)) {
    std::ostringstream s;
    s << "tolerance and net_tolerance must be finite and > 0 (got " << tolerance << ", "
      << netTolerance << ")";
    throw std::invalid_argument(s.str());
  }
}

NetSize chooseNetSize(const std::vector<StreakGrid>& frames, const ShotFitParams& params) {
  params.validate();
  checkFrames(frames);
  const int maxU = std::max(frames.front().particles, 2);
  const int maxV = std::max(frames.front().lines, 2);
  NetSize size;
  SurfaceFitParams fit = params.fit;
  // Along the streaklines first: the curves the v step then blends. Interpolating them across
  // adds no error at the streaklines, so they may use the whole tolerances.
  size.orderU = fit.orderU = std::min(params.fit.orderU, maxU);
  size.nu = smallestCount(std::max(fit.orderU, 2), maxU, [&](int nu) {
    return everyFrame(frames, [&](const StreakGrid& g) {
      const CurveFitQuality q = curveFitQuality(g, nu, fit);
      return q.maxResidual <= params.tolerance && q.netDeviation <= params.netTolerance;
    });
  });
  // The lines' curves do not depend on nv or the order across: fitted once per frame.
  std::vector<LineCurves> curves(frames.size());
  parallelFor(0, int(frames.size()), [&](int n) {
    curves[std::size_t(n)] = fitLines(frames[std::size_t(n)], size.nu, fit);
  });
  auto good = [&](int nv) {
    std::vector<char> ok(frames.size(), 0);
    parallelFor(0, int(frames.size()), [&](int n) {
      const SurfaceFit f = fitAcross(frames[std::size_t(n)], curves[std::size_t(n)], nv, fit);
      ok[std::size_t(n)] = f.maxResidual <= params.tolerance && f.netDeviation <= params.netTolerance;
    });
    return std::all_of(ok.begin(), ok.end(), [](char c) { return c != 0; });
  };
  // Across the streaklines: the highest order whose interpolating sheet keeps to the
  // tolerances, then the fewest control points with it.
  for (fit.orderV = std::min(params.fit.orderV, maxV); fit.orderV > kMinBlenderOrder; --fit.orderV)
    if (good(maxV)) break;
  size.orderV = fit.orderV;
  size.nv = smallestCount(std::max(std::min(fit.orderV, maxV), 2), maxV, good);
  const std::vector<SurfaceFit> fits = fitShot(frames, size, params.fit);
  for (const SurfaceFit& f : fits) {
    size.maxResidual = std::max(size.maxResidual, f.maxResidual);
    size.netDeviation = std::max(size.netDeviation, f.netDeviation);
    size.netToParticles = std::max(size.netToParticles, f.netToParticles);
  }
  return size;
}

std::vector<SurfaceFit> fitShot(const std::vector<StreakGrid>& frames, const NetSize& size,
                                const SurfaceFitParams& params) {
  SurfaceFitParams fit = params;
  fit.orderU = size.orderU;
  fit.orderV = size.orderV;
  fit.validate();
  checkFrames(frames);
  std::vector<SurfaceFit> out(frames.size());
  parallelFor(0, int(frames.size()), [&](int n) {
    SurfaceFit& f = out[std::size_t(n)];
    f = fitSurface(frames[std::size_t(n)], size.nu, size.nv, fit);
    f.netToParticles = netToParticles(f.surface, frames[std::size_t(n)]);
  });
  return out;
}

}  // namespace plume
