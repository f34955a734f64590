// Tests of the smoke solver: the properties a grid solver must keep (divergence after
// projection, mass conservation, no new extrema, symmetry, determinism across thread counts).
#include "core/parallel.h"
#include "core/rng.h"
#include "solver/advection.h"
#include "solver/mass_conservation.h"
#include "solver/smoke_solver.h"
#include "tests/cell_balls.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

namespace plume {
namespace {

SmokeParams smallParams(glm::ivec3 res) {
  SmokeParams p;
  p.resolution = res;
  p.cellSize = 1.f / float(res.x);
  p.frameDt = 1.f / 24.f;
  p.useCfl = true;
  p.pressureTolerance = 1e-6f;
  p.maxPressureIterations = 500;
  return p;
}

using test::ball;

double total(const ScalarGrid& g) {
  double t = 0.0;
  for (std::size_t n = 0; n < g.count(); ++n) t += g[n];
  return t;
}

void addPlumeSource(SmokeSolver& solver, glm::ivec3 res) {
  SourceSettings s;
  s.density = 1.f;
  s.temperature = 1.f;
  solver.addSource(ball(res, glm::vec3(res.x * 0.5f, res.y * 0.5f, 3.f), 2.5f), s);
}

TEST(Projection, DivergenceFreeWithOpenSides) {
  const glm::ivec3 res(24, 24, 32);
  SmokeSolver solver(smallParams(res));
  addPlumeSource(solver, res);
  for (int f = 0; f < 6; ++f) ASSERT_TRUE(solver.advanceFrame());
  EXPECT_GT(solver.maxSpeed(), 0.01f);
  // max |div u| < 1e-4 max|u| / Δx  <=>  max |Δx div u| / max|u| < 1e-4.
  EXPECT_LT(solver.maxDivergence(), 1e-4f);
}

TEST(Projection, DivergenceFreeWithObstacleAndClosedBox) {
  const glm::ivec3 res(24, 24, 32);
  SmokeParams p = smallParams(res);
  p.boundaries.fill(Boundary::Closed);
  SmokeSolver solver(p);
  addPlumeSource(solver, res);
  solver.addObstacle(ball(res, glm::vec3(12.f, 12.f, 16.f), 5.f), Slip::NoSlip);
  for (int f = 0; f < 6; ++f) ASSERT_TRUE(solver.advanceFrame());
  EXPECT_GT(solver.maxSpeed(), 0.01f);
  EXPECT_LT(solver.maxDivergence(), 1e-4f);
  // No flow enters the obstacle: every face of a solid cell carries the (zero) solid velocity.
  const FlagGrid& t = solver.cellTypes();
  const MacGrid3& u = solver.velocity();
  for (int k = 0; k < res.z; ++k)
    for (int j = 0; j < res.y; ++j)
      for (int i = 0; i < res.x; ++i)
        if (t(i, j, k) == kSolid) {
          ASSERT_EQ(u.u()(i, j, k), 0.f);
          ASSERT_EQ(u.w()(i, j, k + 1), 0.f);
        }
}

TEST(Projection, DivergenceFreeWithFreeSlipObstacleAndOpenSides) {
  const glm::ivec3 res(20, 28, 36);
  SmokeSolver solver(smallParams(res));
  addPlumeSource(solver, res);
  solver.addObstacle(ball(res, glm::vec3(10.f, 14.f, 18.f), 4.f), Slip::FreeSlip);
  for (int f = 0; f < 6; ++f) ASSERT_TRUE(solver.advanceFrame());
  EXPECT_LT(solver.maxDivergence(), 1e-4f);
}

/// A closed box, a density blob and the flow its buoyancy makes; no sources.
std::unique_ptr<SmokeSolver> closedBoxWithBlob(glm::ivec3 res, Advection scheme,
                                               Interpolation interp) {
  SmokeParams p = smallParams(res);
  p.boundaries.fill(Boundary::Closed);
  p.advection = scheme;
  p.interpolation = interp;
  p.pressureTolerance = 1e-4f;
  p.vorticity = 0.3f;
  auto solver = std::make_unique<SmokeSolver>(p);
  for (std::uint32_t c : ball(res, glm::vec3(res) * glm::vec3(0.5f, 0.5f, 0.3f), 5.f).cells) {
    solver->density()[c] = 1.f;
    solver->temperature()[c] = 1.f;
  }
  return solver;
}

TEST(Advection, ClosedBoxWithMassConservationKeepsMassOver100BfeccSteps) {
  // With conserveMass on (the default: restoreMass after each advection), what BFECC loses or
  // gains is put back; this checks that the whole step keeps the closed box's mass within 1%.
  const glm::ivec3 res(32, 32, 32);
  auto owner = closedBoxWithBlob(res, Advection::Bfecc, Interpolation::MonotonicCubic);
  SmokeSolver& solver = *owner;
  ASSERT_TRUE(solver.params().conserveMass);
  const double before = total(solver.density());
  for (int s = 0; s < 100; ++s) solver.step(solver.params().frameDt);
  const double after = total(solver.density());
  EXPECT_GT(solver.maxSpeed(), 0.1f);  // the blob really moved
  EXPECT_NEAR(after / before, 1.0, 0.01);
}

TEST(Advection, MassCorrectionKeepsValuesInRange) {
  // Both directions of restoreMass: a deficit is filled without passing the peak, a surplus is
  // removed without going negative.
  ScalarGrid q({8, 8, 8});
  for (std::size_t n = 0; n < q.count(); ++n) q[n] = float(n % 7) / 6.f;
  const double mass = totalMass(q);
  ScalarGrid up = q, down = q;
  EXPECT_EQ(restoreMass(up, mass * 1.1), 0.0);
  EXPECT_NEAR(totalMass(up), mass * 1.1, 1e-3 * mass);
  EXPECT_EQ(restoreMass(down, mass * 0.9), 0.0);
  EXPECT_NEAR(totalMass(down), mass * 0.9, 1e-3 * mass);
  for (std::size_t n = 0; n < q.count(); ++n) {
    ASSERT_LE(up[n], 1.f);
    ASSERT_GE(up[n], q[n]);
    ASSERT_GE(down[n], 0.f);
    ASSERT_LE(down[n], q[n]);
  }
}

TEST(Advection, MassesOfSeveralFieldsMatchMassesOneByOne) {
  // totalMasses() sums density, heat, fuel and soot together; each must be totalMass() exactly.
  Rng rng(3);
  ScalarGrid fields[4] = {ScalarGrid({9, 7, 5}), ScalarGrid({9, 7, 5}), ScalarGrid({9, 7, 5}),
                          ScalarGrid({9, 7, 5})};
  for (ScalarGrid& g : fields)
    for (std::size_t n = 0; n < g.count(); ++n) g[n] = float(rng.uniform(0.0, 2.0));
  const ScalarGrid* q[4] = {&fields[0], &fields[1], &fields[2], &fields[3]};
  const float background[4] = {0.f, 0.25f, 0.f, -1.f};
  double out[4];
  float peaks[4];
  totalMasses(q, background, 4, out, peaks);
  for (int f = 0; f < 4; ++f) {
    EXPECT_EQ(out[f], totalMass(fields[f], background[f])) << f;
    float peak = 0.f;
    for (std::size_t n = 0; n < fields[f].count(); ++n) peak = std::max(peak, fields[f][n] - background[f]);
    EXPECT_EQ(peaks[f], peak) << f;
  }
  // restoreMasses() of all four (a surplus, two deficits, one too large to fill) gives each
  // field exactly what restoreMass() gives it alone.
  const double targets[4] = {out[0] * 0.9, out[1] * 1.05, out[2] * 1.2, out[3] * 3.0};
  ScalarGrid alone[4] = {fields[0], fields[1], fields[2], fields[3]};
  double missingAlone[4], missing[4];
  for (int f = 0; f < 4; ++f) missingAlone[f] = restoreMass(alone[f], targets[f], background[f]);
  ScalarGrid* grids[4] = {&fields[0], &fields[1], &fields[2], &fields[3]};
  restoreMasses(grids, targets, background, 4, out, peaks, missing);
  for (int f = 0; f < 4; ++f) {
    EXPECT_EQ(fields[f].values(), alone[f].values()) << f;
    EXPECT_EQ(missing[f], missingAlone[f]) << f;
  }
  EXPECT_GT(missing[3], 0.0);  // 3x the mass does not fit under the peak
}

TEST(Advection, MassCorrectionInTheMaskMatchesTheWholeGrid) {
  // Smoke in one corner of a 64³ grid: with the block mask the totals and the correction read
  // only the blocks near it, and must give what the whole grid gives, bit for bit.
  const glm::ivec3 n(64, 64, 64);
  Rng rng(4);
  ScalarGrid density(n), heat(n, 0.25f);
  for (int k = 0; k < 12; ++k)
    for (int j = 0; j < 10; ++j)
      for (int i = 0; i < 9; ++i) {
        density(i, j, k) = float(rng.uniform(0.0, 1.0));
        heat(i, j, k) = 0.25f + float(rng.uniform(0.0, 2.0));
      }
  BlockMask mask, other;
  mask.build(density, 0.f);
  other.build(heat, 0.25f);
  mask.merge(other);
  ASSERT_LT(mask.fill(), 0.5f);
  const float background[2] = {0.f, 0.25f};
  for (double factor : {0.8, 1.1}) {
    ScalarGrid a[2] = {density, heat}, b[2] = {density, heat};
    ScalarGrid* ga[2] = {&a[0], &a[1]};
    ScalarGrid* gb[2] = {&b[0], &b[1]};
    double ma[2], mb[2];
    float pa[2], pb[2];
    totalMasses(ga, background, 2, ma, pa);
    totalMasses(gb, background, 2, mb, pb, &mask);
    for (int f = 0; f < 2; ++f) {
      EXPECT_EQ(ma[f], mb[f]);
      EXPECT_EQ(pa[f], pb[f]);
    }
    const double targets[2] = {ma[0] * factor, ma[1] * factor};
    restoreMasses(ga, targets, background, 2, ma, pa);
    restoreMasses(gb, targets, background, 2, mb, pb, nullptr, &mask);
    for (int f = 0; f < 2; ++f) EXPECT_EQ(a[f].values(), b[f].values()) << factor;
  }
}

TEST(Advection, OpenSidesLetSmokeLeave) {
  // The mass correction must not hold smoke in: a blob blown out through an open side is gone.
  const glm::ivec3 res(24, 12, 12);
  SmokeParams p = smallParams(res);
  p.alpha = p.beta = p.vorticity = 0.f;
  SmokeSolver solver(p);
  solver.velocity().u().fill(1.f);
  for (std::uint32_t c : ball(res, glm::vec3(18.f, 6.f, 6.f), 3.f).cells) solver.density()[c] = 1.f;
  for (int f = 0; f < 24; ++f) ASSERT_TRUE(solver.advanceFrame());  // 1 m: through the +x side
  EXPECT_LT(total(solver.density()), 1e-3);
}

TEST(Advection, MonotonicCubicMakesNoNewExtrema) {
  const glm::ivec3 res(32, 32, 32);
  for (Advection scheme : {Advection::SemiLagrangian, Advection::Bfecc, Advection::MacCormack}) {
    auto owner = closedBoxWithBlob(res, scheme, Interpolation::MonotonicCubic);
    SmokeSolver& solver = *owner;
    for (int s = 0; s < 40; ++s) {
      solver.step(solver.params().frameDt);
      float lo = 1e9f, hi = -1e9f;
      for (std::size_t n = 0; n < solver.density().count(); ++n) {
        lo = std::min(lo, solver.density()[n]);
        hi = std::max(hi, solver.density()[n]);
      }
      ASSERT_GE(lo, 0.f) << "step " << s;
      ASSERT_LE(hi, 1.f) << "step " << s;
    }
  }
}

/// A smooth (Gaussian) blob of σ = 2.5 cells around cell coordinates c: on a top-hat the
/// limiters of the monotone schemes bias the centroid.
void addGaussianBlob(ScalarGrid& density, glm::vec3 c) {
  const glm::ivec3 n = density.size();
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const glm::vec3 d = glm::vec3(i, j, k) + 0.5f - c;
        density(i, j, k) = std::exp(-glm::dot(d, d) / (2.f * 2.5f * 2.5f));
      }
}

/// x of the density's centroid, in cells.
double centroidX(const ScalarGrid& density) {
  const glm::ivec3 n = density.size();
  double m = 0, mx = 0;
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        m += density(i, j, k);
        mx += density(i, j, k) * (i + 0.5);
      }
  return mx / m;
}

/// A constant stream through the open sides: the air outside must move too (the wind), or the
/// still air that enters through the upwind side would slow it down (solver/inflow.h).
void blowWind(SmokeParams& p, float speed) {
  p.wind = glm::vec3(speed, 0.f, 0.f);
  p.windStrength = 1.f;
}

TEST(Advection, ConstantWindCarriesBlobAtItsSpeed) {
  const glm::ivec3 res(40, 12, 12);
  SmokeParams p = smallParams(res);
  p.alpha = p.beta = 0.f;
  p.vorticity = 0.f;
  blowWind(p, 0.5f);
  SmokeSolver solver(p);
  solver.velocity().u().fill(0.5f);  // m/s, divergence free
  addGaussianBlob(solver.density(), {10.f, 6.f, 6.f});
  const double x0 = centroidX(solver.density());
  for (int f = 0; f < 12; ++f) ASSERT_TRUE(solver.advanceFrame());
  // 0.5 m/s for 0.5 s = 0.25 m = 10 cells; 0.1 cell is 1% of the distance travelled.
  EXPECT_NEAR(centroidX(solver.density()) - x0, 10.0, 0.1);
}

TEST(Advection, MacCormackCarriesBlobAtItsSpeed) {
  // Selle et al. 2008: in a constant wind MacCormack moves a smooth blob as far as the wind does
  // and keeps its peak better than the first-order semi-Lagrangian step.
  const glm::ivec3 res(40, 12, 12);
  auto run = [&](Advection scheme, double& shift, float& peak) {
    SmokeParams p = smallParams(res);
    p.alpha = p.beta = p.vorticity = 0.f;
    p.advection = scheme;
    p.conserveMass = false;
    blowWind(p, 0.5f);
    SmokeSolver solver(p);
    solver.velocity().u().fill(0.5f);
    addGaussianBlob(solver.density(), {10.f, 6.f, 6.f});
    const double x0 = centroidX(solver.density());
    for (int f = 0; f < 12; ++f) ASSERT_TRUE(solver.advanceFrame());
    shift = centroidX(solver.density()) - x0;
    peak = *std::max_element(solver.density().values().begin(), solver.density().values().end());
  };
  double shiftMac = 0, shiftSl = 0;
  float peakMac = 0, peakSl = 0;
  run(Advection::MacCormack, shiftMac, peakMac);
  run(Advection::SemiLagrangian, shiftSl, peakSl);
  EXPECT_NEAR(shiftMac, 10.0, 0.1);  // 0.5 m/s for 0.5 s = 10 cells
  EXPECT_GT(peakMac, peakSl);
  EXPECT_LE(peakMac, 1.f);
}

TEST(Advection, SharedTracesMatchTraceBackBitForBit) {
  // Advector::trace() computes the first RK2 velocity sample from tabulated face averages and
  // traces four samples at a time; each traced position must still be exactly traceBack().
  // Semi-Lagrangian linear advection of a field reads it at the traced positions only.
  Rng rng(5);
  const glm::ivec3 n(11, 7, 6);
  MacGrid3 velocity(n);
  for (int a = 0; a < 3; ++a)
    for (std::size_t c = 0; c < velocity.component(a).count(); ++c)
      velocity.component(a)[c] = rng.uniform(-3.f, 3.f);
  const glm::vec3 offsets[4] = {kCellOffset, kFaceOffsetU, kFaceOffsetV, kFaceOffsetW};
  const glm::ivec3 sizes[4] = {n, velocity.u().size(), velocity.v().size(), velocity.w().size()};
  Advector advector;
  advector.reserve(velocity.u().count() + velocity.v().count() + velocity.w().count());
  const float dt = 0.4f, h = 0.5f, cells = dt / h;
  for (int layout = 0; layout < 4; ++layout) {
    const glm::ivec3 size = sizes[layout];
    ScalarGrid field(size), out;
    for (std::size_t c = 0; c < field.count(); ++c) field[c] = rng.uniform(-1.f, 1.f);
    advector.trace(velocity, size, offsets[layout], dt, h, Advection::SemiLagrangian, nullptr);
    advector.advect(field, out, Interpolation::Linear, nullptr, 0.f);
    for (int k = 0; k < size.z; ++k)
      for (int j = 0; j < size.y; ++j)
        for (int i = 0; i < size.x; ++i) {
          const glm::vec3 p = glm::vec3(i, j, k) + offsets[layout];
          const glm::vec3 q = traceBack(velocity, p, cells) - offsets[layout];
          ASSERT_EQ(out(i, j, k), sampleLinear(field, q)) << layout << " " << i << " " << j << " " << k;
        }
  }
}

TEST(Solver, SymmetricPlumeStaysSymmetric) {
  const glm::ivec3 res(24, 24, 32);
  SmokeParams p = smallParams(res);
  p.boundaries[kNegZ] = Boundary::Closed;
  SmokeSolver solver(p);
  addPlumeSource(solver, res);
  for (int s = 0; s < 50; ++s) solver.step(p.frameDt * 0.5f);
  const ScalarGrid& d = solver.density();
  float peak = 0.f, err = 0.f;
  for (int k = 0; k < res.z; ++k)
    for (int j = 0; j < res.y; ++j)
      for (int i = 0; i < res.x; ++i) {
        peak = std::max(peak, d(i, j, k));
        err = std::max(err, std::fabs(d(i, j, k) - d(res.x - 1 - i, j, k)));
        err = std::max(err, std::fabs(d(i, j, k) - d(i, res.y - 1 - j, k)));
      }
  EXPECT_GT(peak, 0.5f);
  EXPECT_LT(err, 1e-4f * peak);
}

TEST(Solver, SameResultWithOneAndTwoThreads) {
  const glm::ivec3 res(20, 24, 28);
  for (const bool linearVelocity : {false, true}) {
    SCOPED_TRACE(linearVelocity ? "Fast Velocity" : "cubic velocity");
    auto run = [&](int threads) {
      SmokeParams p = smallParams(res);
      p.threads = threads;
      p.linearVelocity = linearVelocity;
      p.combustion = true;
      p.conductivity = 1e-3f;
      auto owner = std::make_unique<SmokeSolver>(p);
      SmokeSolver& solver = *owner;
      SourceSettings s;
      s.fuel = 1.f;
      s.velocity = glm::vec3(0.1f, 0.f, 0.3f);
      solver.addSource(ball(res, glm::vec3(9.f, 12.f, 4.f), 3.f), s);
      solver.addObstacle(ball(res, glm::vec3(10.f, 12.f, 16.f), 3.f), Slip::FreeSlip);
      for (int f = 0; f < 8; ++f) solver.advanceFrame();
      return owner;
    };
    auto pa = run(1), pb = run(2);
    const SmokeSolver &a = *pa, &b = *pb;
    EXPECT_EQ(a.density().values(), b.density().values());
    EXPECT_EQ(a.temperature().values(), b.temperature().values());
    EXPECT_EQ(a.soot().values(), b.soot().values());
    EXPECT_EQ(a.velocity().w().values(), b.velocity().w().values());
  }
}

TEST(Solver, FastVelocityCarriesTheVelocityTrilinearly) {
  // linearVelocity changes only how the velocity is carried: the same scene differs after a
  // few frames, and with trilinear interpolation everywhere it changes nothing.
  const glm::ivec3 res(16, 16, 20);
  auto run = [&](Interpolation interp, bool linearVelocity) {
    SmokeParams p = smallParams(res);
    p.interpolation = interp;
    p.linearVelocity = linearVelocity;
    SmokeSolver solver(p);
    SourceSettings s;
    s.velocity = glm::vec3(0.2f, 0.f, 0.4f);
    solver.addSource(ball(res, glm::vec3(8.f, 8.f, 4.f), 3.f), s);
    for (int f = 0; f < 4; ++f) solver.advanceFrame();
    return solver.velocity().w().values();
  };
  EXPECT_NE(run(Interpolation::MonotonicCubic, false), run(Interpolation::MonotonicCubic, true));
  EXPECT_EQ(run(Interpolation::Linear, false), run(Interpolation::Linear, true));
}

TEST(Combustion, FuelBurnsIntoSootAndHeat) {
  const glm::ivec3 res(16, 16, 16);
  SmokeParams p = smallParams(res);
  p.combustion = true;
  p.alpha = p.beta = 0.f;
  p.vorticity = 0.f;
  p.coolingRate = 0.f;
  p.expansion = 0.f;
  p.boundaries.fill(Boundary::Closed);
  SmokeSolver solver(p);
  solver.fuel()(8, 8, 8) = 1.f;
  solver.burn(0.1f);
  // F(t) = F0 e^{-r t}; S and T gain k_S and k_T times what burnt (eqs. 3-5).
  const float burnt = 1.f - std::exp(-p.burnRate * 0.1f);
  EXPECT_NEAR(solver.fuel()(8, 8, 8), 1.f - burnt, 1e-6f);
  EXPECT_NEAR(solver.soot()(8, 8, 8), p.sootYield * burnt, 1e-6f);
  EXPECT_NEAR(solver.temperature()(8, 8, 8), p.heatYield * burnt, 1e-6f);
  EXPECT_GT(solver.flame()(8, 8, 8), 0.f);
}

TEST(Params, ValidateNamesTheSetting) {
  SmokeParams p;
  p.vorticity = -1.f;
  try {
    p.validate();
    FAIL() << "negative vorticity accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("vorticity"), std::string::npos);
  }
  p = SmokeParams();
  p.alpha = std::nanf("");
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = SmokeParams();
  p.resolution = glm::ivec3(0, 10, 10);
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p.resolution = glm::ivec3(1000, 1000, 1000);
  EXPECT_THROW(p.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace plume
