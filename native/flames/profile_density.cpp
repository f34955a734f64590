/// \file profile_density.cpp
/// Eq. 4: exact closest points on the profile's surface of revolution, quadrature and sampling.

#include "flames/profile_density.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kRadialCells = 32;  ///< cells across ρ ∈ [0, rhoMax]
constexpr int kQuadrature = 4;    ///< midpoint samples per cell side
constexpr std::uint8_t kMixed = 0, kInside = 1, kOutside = 2;  ///< mCellSide
/// Margin (widest radii) of the cell classes: far above the rounding of a drawn (ρ, z), which can
/// pass its cell's far edge by an ulp.
constexpr double kSideMargin = 1e-9;

}  // namespace

double glowWindow(double dist, double shell) {
  const double t = std::clamp(2.0 * dist / shell - 1.0, 0.0, 1.0);
  return 1.0 - t * t * (3.0 - 2.0 * t);
}

void DensityParams::validate() const {
  if (!(falloff > 0.0 && falloff <= 100.0))
    throw std::invalid_argument("falloff must be in (0, 100] widest radii (got " + std::to_string(falloff) + ")");
  if (!(cutoff > 0.0 && cutoff <= 20.0))
    throw std::invalid_argument("cutoff must be in (0, 20] falloff lengths (got " + std::to_string(cutoff) + ")");
}

inline double ProfileDensity::distance2ToSegment(int segment, glm::dvec2 p, glm::dvec2* closest) const {
  const glm::dvec2 a = mSegA[std::size_t(segment)];
  const glm::dvec2 ab = mSegAb[std::size_t(segment)];
  const double len2 = mSegLen2[std::size_t(segment)];
  const double t = len2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  *closest = a + t * ab;
  const glm::dvec2 d = p - *closest;
  return glm::dot(d, d);
}

double ProfileDensity::distanceToSegment(int segment, glm::dvec2 p, glm::dvec2* closest) const {
  return std::sqrt(distance2ToSegment(segment, p, closest));
}

ProfileDensity::ProfileDensity(const FlameProfile& profile, const DensityParams& params)
    : mProfile(profile), mParams(params) {
  params.validate();
  mShell = params.cutoff * params.falloff;
  mRhoMax = 1.0 + mShell;
  mZMin = -mShell;
  mZMax = profile.aspect() + mShell;
  mNr = kRadialCells;
  mCell = mRhoMax / mNr;
  mNz = int(std::ceil((mZMax - mZMin) / mCell));
  mZMax = mZMin + mNz * mCell;
  const int segments = int(profile.meridian().size()) - 1;
  const int cells = mNr * mNz;
  for (int j = 0; j < segments; ++j) {
    const glm::dvec2 a = profile.meridian()[std::size_t(j)], b = profile.meridian()[std::size_t(j) + 1];
    mSegA.push_back(a);
    mSegAb.push_back(b - a);
    mSegLen2.push_back(glm::dot(b - a, b - a));
  }
  for (int c = 0; c < cells; ++c) mCellOrigin.emplace_back((c % mNr) * mCell, mZMin + (c / mNr) * mCell);
  classifyCells();

  // Candidates: segment j can be closest to a point of a cell (centre c, half-diagonal hd) only
  // if dist(c, j) - hd <= min_k dist(c, k) + hd (the nearest distance in the cell is at most
  // min_k dist(c, k) + hd, and segment j is at least dist(c, j) - hd away).
  const double hd = 0.5 * std::sqrt(2.0) * mCell;
  std::vector<double> dist(std::size_t(segments), 0.0);
  mCandidateStart.assign(std::size_t(cells) + 1, 0);
  for (int c = 0; c < cells; ++c) {
    const glm::dvec2 centre((c % mNr + 0.5) * mCell, mZMin + (c / mNr + 0.5) * mCell);
    double best = std::numeric_limits<double>::max();
    glm::dvec2 q;
    for (int j = 0; j < segments; ++j) best = std::min(best, dist[std::size_t(j)] = distanceToSegment(j, centre, &q));
    for (int j = 0; j < segments; ++j)
      if (dist[std::size_t(j)] <= best + 2.0 * hd) mCandidates.push_back(j);
    mCandidateStart[std::size_t(c) + 1] = int(mCandidates.size());
  }

  // Cell masses ∫ 2πρ d 1[dist <= shell] and ∫ 2πρ d² 1[...] by midpoint quadrature.
  std::vector<double> cellMass(std::size_t(cells), 0.0), cellMean(std::size_t(cells), 0.0);
  mCellMaxDensity.assign(std::size_t(cells), 0.0);
  double mass = 0.0, mass2 = 0.0;
  const double h = mCell / kQuadrature, l2 = params.falloff * params.falloff;
  for (int c = 0; c < cells; ++c) {
    const double r0 = (c % mNr) * mCell, z0 = mZMin + (c / mNr) * mCell;
    double m = 0.0, m2 = 0.0;
    for (int a = 0; a < kQuadrature; ++a)
      for (int b = 0; b < kQuadrature; ++b) {
        const glm::dvec2 p(r0 + (a + 0.5) * h, z0 + (b + 0.5) * h);
        const double dd = surfaceDistance(p);
        if (dd > mShell) continue;
        const double d = glowWindow(dd, mShell) / (1.0 + dd * dd / l2);
        m += 2.0 * kPi * p.x * d * h * h;
        m2 += 2.0 * kPi * p.x * d * d * h * h;
      }
    mass += m;
    mass2 += m2;
    cellMass[std::size_t(c)] = m;
    cellMean[std::size_t(c)] = m > 0.0 ? m2 / m : 0.0;
    // Bound for rejection: the cell is at least (distance at its centre - hd) from the surface.
    const double dc = surfaceDistance({r0 + 0.5 * mCell, z0 + 0.5 * mCell});
    const double near = std::max(0.0, dc - hd);
    mCellMaxDensity[std::size_t(c)] = glowWindow(near, mShell) / (1.0 + near * near / l2);
  }
  // Strata ordered by the cells' mean d: consecutive samples then fall in cells of alike d at
  // any count, so the stratification removes most of the variance of mean d(x_i) (eq. 6's sum).
  mOrder.resize(std::size_t(cells));
  for (int c = 0; c < cells; ++c) mOrder[std::size_t(c)] = c;
  std::stable_sort(mOrder.begin(), mOrder.end(),
                   [&](int a, int b) { return cellMean[std::size_t(a)] < cellMean[std::size_t(b)]; });
  mCumulative.assign(std::size_t(cells), 0.0);
  double run = 0.0;
  for (int k = 0; k < cells; ++k) mCumulative[std::size_t(k)] = (run += cellMass[std::size_t(mOrder[std::size_t(k)])]) / mass;
  mCumulative.back() = 1.0;
  // Guide table: bucket b of u ∈ [b/G, (b+1)/G) starts its search at upper_bound(b/G).
  mGuide.resize(std::size_t(cells));
  for (int b = 0; b < cells; ++b)
    mGuide[std::size_t(b)] = int(std::upper_bound(mCumulative.begin(), mCumulative.end(), double(b) / cells) -
                                 mCumulative.begin());
  mMass = mass;
  mMeanDensity = mass2 / mass;
}

int ProfileDensity::cellOf(glm::dvec2 p) const {
  const int i = int(std::floor(p.x / mCell)), k = int(std::floor((p.y - mZMin) / mCell));
  if (i < 0 || i >= mNr || k < 0 || k >= mNz) return -1;
  return k * mNr + i;
}

glm::dvec2 ProfileDensity::closestPoint(glm::dvec2 p, double* distance) const {
  // Squared distances, one square root: √ is monotonic, so the distance is the same.
  const int cell = cellOf(p);
  double best = std::numeric_limits<double>::max();
  glm::dvec2 out(0.0), q;
  auto consider = [&](int j) {
    const double d2 = distance2ToSegment(j, p, &q);
    if (d2 < best) best = d2, out = q;
  };
  if (cell >= 0) {
    for (int n = mCandidateStart[std::size_t(cell)]; n < mCandidateStart[std::size_t(cell) + 1]; ++n)
      consider(mCandidates[std::size_t(n)]);
  } else {
    for (int j = 0; j + 1 < int(mProfile.meridian().size()); ++j) consider(j);
  }
  *distance = std::sqrt(best);
  return out;
}

double ProfileDensity::surfaceDistance(glm::dvec2 rhoZ) const {
  if (inside(rhoZ)) return 0.0;
  double dist;
  closestPoint(rhoZ, &dist);
  return dist;
}

double ProfileDensity::density(const glm::dvec3& p) const {
  const double dist = surfaceDistance({std::hypot(p.x, p.y), p.z});
  return glowWindow(dist, mShell) / (1.0 + dist * dist / (mParams.falloff * mParams.falloff));
}

void ProfileDensity::classifyCells() {
  // The radius is piecewise linear in s = z / aspect: its extremes over a cell's z-range are at
  // the range's ends or at the profile's breakpoints in it (both sides of a jump at one s).
  const double a = mProfile.aspect();
  mCellSide.assign(mCellOrigin.size(), kMixed);
  mCellRadius.assign(mCellOrigin.size(), glm::dvec2(0.0));
  for (std::size_t c = 0; c < mCellOrigin.size(); ++c) {
    const double r0 = mCellOrigin[c].x, z0 = mCellOrigin[c].y, r1 = r0 + mCell, z1 = z0 + mCell;
    if (z1 < -kSideMargin || z0 > a + kSideMargin) {
      mCellSide[c] = kOutside;
      continue;
    }
    const double s0 = std::clamp(z0 / a, 0.0, 1.0), s1 = std::clamp(z1 / a, 0.0, 1.0);
    const double e0 = mProfile.radius(s0), e1 = mProfile.radius(s1);
    double lo = std::min(e0, e1), hi = std::max(e0, e1);
    for (const glm::dvec2& q : mProfile.points())
      if (q.x >= s0 && q.x <= s1) lo = std::min(lo, q.y), hi = std::max(hi, q.y);
    mCellRadius[c] = {lo, hi};
    if (z0 > kSideMargin && z1 < a - kSideMargin && r1 + kSideMargin < lo)
      mCellSide[c] = kInside;
    else if (r0 > hi + kSideMargin)
      mCellSide[c] = kOutside;
  }
}

bool ProfileDensity::inside(glm::dvec2 p) const {
  const double a = mProfile.aspect();
  return p.y >= 0.0 && p.y <= a && p.x <= mProfile.radius(p.y / a);
}

ProfileSample ProfileDensity::sample(double u, Rng& rng) const {
  // upper_bound(mCumulative, u) from the guide: a step or two either way.
  const int size = int(mCumulative.size());
  int k = mGuide[std::size_t(std::clamp(u * size, 0.0, double(size - 1)))];
  while (k > 0 && mCumulative[std::size_t(k) - 1] > u) --k;
  while (k < size && mCumulative[std::size_t(k)] <= u) ++k;
  const int c = mOrder[std::size_t(std::min(k, size - 1))];
  const double r0 = mCellOrigin[std::size_t(c)].x, z0 = mCellOrigin[std::size_t(c)].y;
  const double bound = mCellMaxDensity[std::size_t(c)], l2 = mParams.falloff * mParams.falloff;
  ProfileSample s;
  // Rejection inside the cell: uniform in volume (ρ drawn ∝ ρ), accepted with d / bound. A cell
  // with mass has a region inside the shell; 256 tries make a miss practically impossible and
  // keep the loop bounded (the last candidate is then kept).
  double rho = 0.0, theta = 0.0;
  const std::uint8_t side = mCellSide[std::size_t(c)];
  for (int attempt = 0; attempt < 256; ++attempt) {
    rho = std::sqrt(r0 * r0 + rng.uniform() * ((r0 + mCell) * (r0 + mCell) - r0 * r0));
    const double z = z0 + rng.uniform() * mCell;
    theta = 2.0 * kPi * rng.uniform();
    // The cell's class saves the queries whose answer it knows (the same values as the queries').
    double dist = 0.0;
    if (side == kOutside) {
      closestPoint({rho, z}, &dist);
    } else if (side == kMixed) {
      // inside() spelled out with the cell's radius bounds: the profile's radius only between them.
      const glm::dvec2 bounds = mCellRadius[std::size_t(c)];
      const bool within = z >= 0.0 && z <= mProfile.aspect();
      if (within && rho + kSideMargin < bounds.x) {
        dist = 0.0;
      } else if (!within || rho > bounds.y + kSideMargin) {
        closestPoint({rho, z}, &dist);
      } else {
        dist = surfaceDistance({rho, z});
      }
    }
    const double d = glowWindow(dist, mShell) / (1.0 + dist * dist / l2);
    s.position.z = z;
    s.density = d;
    s.inside = dist == 0.0;  // surfaceDistance is 0 exactly inside the surface
    if (dist < mShell && rng.uniform() * bound <= d) break;
  }
  // The angle only places the accepted candidate: its cosine and sine once, in single precision
  // (positions end as floats; θ ∈ [0, 2π) to ~2e-7 rad).
  s.position.x = rho * double(std::cos(float(theta)));
  s.position.y = rho * double(std::sin(float(theta)));
  return s;
}

}  // namespace plume
