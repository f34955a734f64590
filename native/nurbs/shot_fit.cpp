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

/// True when f(n) holds for every frame n < count (each frame on its own task; the answer is
/// order-free).
bool everyFrame(std::size_t count, const std::function<bool(std::size_t)>& f) {
  std::vector<char> ok(count, 0);
  parallelFor(0, int(count), [&](int n) { ok[std::size_t(n)] = f(std::size_t(n)); });
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

/// ν of a frame: params.particleTolerance, or half the largest gap between consecutive kept
/// particles of a streakline when that is larger (early in a shot the particles of a fast
/// source are many cells apart, and a control point on the sheet between two of them cannot be
/// within 3 cells of either).
double frameNearTolerance(const StreakGrid& g, double particleTolerance) {
  double gap = 0.0;
  for (int b = 0; b < g.lines; ++b) {
    int last = -1;
    for (int a = 0; a < g.particles; ++a) {
      if (!g.kept(b, a)) continue;
      if (last >= 0) gap = std::max(gap, double(glm::length(g.at(b, a) - g.at(b, last))));
      last = a;
    }
  }
  return std::max(particleTolerance, 0.5 * gap);
}

/// Counts above the one bisected on ε and δ that are tried for ν before the largest count (each
/// try fits every frame's streaklines once).
constexpr int kNearScanCounts = 8;

}  // namespace

void ShotFitParams::validate() const {
  fit.validate();
  if (!std::isfinite(tolerance) || !(tolerance > 0.0) || !std::isfinite(netTolerance) ||
      !(netTolerance > 0.0) || !std::isfinite(particleTolerance) || !(particleTolerance > 0.0)) {
    std::ostringstream s;
    s << "tolerance, net_tolerance and particle_tolerance must be finite and > 0 (got "
      << tolerance << ", " << netTolerance << ", " << particleTolerance << ")";
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
  // Each frame's kept particles, bucketed once for ν.
  std::vector<NearParticles> near;
  near.reserve(frames.size());
  std::vector<double> nearTolerance;
  for (const StreakGrid& g : frames) {
    near.push_back(keptParticles(g));
    nearTolerance.push_back(frameNearTolerance(g, params.particleTolerance));
  }
  // The counts are bisected on ε and δ, which tighten as the count grows; ν need not (more
  // control points on sparse particles may sit farther from them), so it is checked at the
  // count found and the few above it, and the largest count is the fallback.
  // Along the streaklines first: the curves the v step then blends. Interpolating them across
  // adds no error at the streaklines, so they may use the whole tolerances.
  auto fitsU = [&](int nu, bool checkNear) {
    return everyFrame(frames.size(), [&](std::size_t n) {
      const CurveFitQuality q = curveFitQuality(frames[n], nu, fit, checkNear ? &near[n] : nullptr);
      return q.maxResidual <= params.tolerance && q.netDeviation <= params.netTolerance &&
             (!checkNear || q.netToParticles <= nearTolerance[n]);
    });
  };
  // The count at the current order along u, 0 when no count meets the three tolerances. Orders
  // below the first are tried only where the largest count meets them; the particle net needs
  // none (its control points are the particles), so it is the last.
  // ν can miss at the count found and at the largest by a fraction of a cell where a frame's
  // particles are sparse (gaps of many cells early in a shot: a control point that lands mid-gap
  // at one count lands beside a particle at the next), so the next kNearScanCounts counts are
  // tried before the largest: a sphere source's 256 streaklines over 60 frames with Fast Velocity
  // missed a ν of 3 cells on every frame at the 38 found (3.01 cells) and at 113 (3.16) but met
  // it at 40 (2.87), where trying 38 and 113 alone dropped the whole sheet to order 2 (113 x 256
  // flat facets); with ν of the frame (its particles 13 cells apart early on) 38 meets it.
  // Where no count of order 4 or 3 meets the tolerances, the particle net at the first order
  // (control points on the particles, ν = 0, the sheet C²) instead of order 2 (the same control
  // points drawn as flat facets).
  const int firstU = std::min(params.fit.orderU, maxU);
  auto countU = [&]() {
    if (fit.orderU <= kMinBlenderOrder && firstU > kMinBlenderOrder) {
      fit.orderU = firstU;
      fit.particleNetU = true;
      return maxU;
    }
    const bool last = fit.orderU <= kMinBlenderOrder;
    if (fit.orderU < firstU && !last && !fitsU(maxU, true)) return 0;
    const int nu =
        smallestCount(std::max(fit.orderU, 2), maxU, [&](int n) { return fitsU(n, false); });
    const int scanEnd = std::min(maxU, nu + kNearScanCounts);
    for (int n = nu; n <= scanEnd; ++n)
      if (fitsU(n, true)) return n;
    if (scanEnd < maxU && fitsU(maxU, true)) return maxU;
    return last ? maxU : 0;
  };
  for (fit.orderU = firstU;; --fit.orderU)
    if ((size.nu = countU()) > 0) break;
  size.orderU = fit.orderU;
  size.particleNetU = fit.particleNetU;
  // The lines' curves do not depend on nv or the order across: fitted once per frame.
  std::vector<LineCurves> curves(frames.size());
  parallelFor(0, int(frames.size()), [&](int n) {
    curves[std::size_t(n)] = fitLines(frames[std::size_t(n)], size.nu, fit);
  });
  auto fitsV = [&](int nv, bool checkNear) {
    return everyFrame(frames.size(), [&](std::size_t n) {
      const SurfaceFit f = fitAcross(frames[n], curves[n], nv, fit);
      return f.maxResidual <= params.tolerance && f.netDeviation <= params.netTolerance &&
             (!checkNear || netToParticles(f.surface, near[n]) <= nearTolerance[n]);
    });
  };
  // Across the streaklines: the highest order whose interpolating sheet keeps to the
  // tolerances, then the fewest control points with it.
  const int firstV = std::min(params.fit.orderV, maxV);
  for (fit.orderV = firstV; fit.orderV > kMinBlenderOrder; --fit.orderV)
    if (fitsV(maxV, true)) break;
  // Before order 2 across, the particle net across (rows = the lines' curves, so ν holds as it
  // does for them), where every frame has all maxV lines (a line with no kept particle has no
  // curve to be a row). Its sheet is C² across and cuts each zig-zag of neighbouring lines by
  // |Δ²p|/6, as the particle net along u does: lines that cross in a stirred plume make the
  // greedy order zig-zag, and order 2 drew those zig-zags as creased facets that show in any
  // close-up.
  if (fit.orderV <= kMinBlenderOrder && firstV > kMinBlenderOrder) {
    const bool allLines = everyFrame(frames.size(), [&](std::size_t n) {
      return int(curves[n].lines.size()) == maxV;
    });
    if (allLines) {
      fit.orderV = firstV;
      fit.particleNetV = true;
    }
  }
  size.orderV = fit.orderV;
  size.particleNetV = fit.particleNetV;
  if (fit.particleNetV) {
    size.nv = maxV;
  } else {
    size.nv = smallestCount(std::max(std::min(fit.orderV, maxV), 2), maxV,
                            [&](int n) { return fitsV(n, false); });
    if (size.nv < maxV && !fitsV(size.nv, true)) size.nv = maxV;
  }
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
  fit.particleNetU = size.particleNetU;
  fit.particleNetV = size.particleNetV;
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
