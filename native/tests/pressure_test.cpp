// Unit tests of the MGPCG pressure solve (McAdams et al. 2010): operator properties, convergence
// with open/closed sides and obstacles, resolution independence, determinism, exact solutions.
#include "solver/pressure.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>

#include "core/parallel.h"

namespace plume {
namespace {

using Sides = std::array<Boundary, 6>;
constexpr Boundary O = Boundary::Open;
constexpr Boundary C = Boundary::Closed;
const Sides kAllOpen{O, O, O, O, O, O};
const Sides kAllClosed{C, C, C, C, C, C};
const Sides kOpenTop{C, C, C, C, C, O};
const Sides kMixed{O, C, C, O, C, O};

enum class Obstacle { None, Sphere, WallBlock };

/// Cell types: a solid sphere in the middle, or a solid block standing on the -x wall.
FlagGrid makeTypes(glm::ivec3 n, Obstacle obstacle) {
  FlagGrid t(n, kFluid);
  const glm::vec3 c = glm::vec3(n) * 0.5f;
  const float radius = 0.2f * float(std::min(n.x, std::min(n.y, n.z)));
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const glm::vec3 p = glm::vec3(i, j, k) + 0.5f;
        bool solid = false;
        if (obstacle == Obstacle::Sphere) solid = glm::length(p - c) < radius;
        if (obstacle == Obstacle::WallBlock)
          solid = i < n.x / 4 && j > n.y / 3 && j < 2 * n.y / 3 && k < n.z / 2;
        t(i, j, k) = solid ? kSolid : kFluid;
      }
  return t;
}

ScalarGrid randomField(glm::ivec3 n, unsigned seed, const FlagGrid* types = nullptr) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  ScalarGrid g(n);
  for (std::size_t c = 0; c < g.count(); ++c) {
    g[c] = u(gen);
    if (types && (*types)[c] == kSolid) g[c] = 0.f;
  }
  return g;
}

double dot(const ScalarGrid& a, const ScalarGrid& b) {
  double s = 0.0;
  for (std::size_t c = 0; c < a.count(); ++c) s += double(a[c]) * b[c];
  return s;
}

/// Reference operator of pressure.h in double, straight from its definition.
std::vector<double> referenceOperator(const FlagGrid& types, const Sides& sides,
                                      const ScalarGrid& x) {
  const glm::ivec3 n = types.size();
  std::vector<double> y(x.count(), 0.0);
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        if (types(i, j, k) != kFluid) continue;
        double s = 0.0;
        const glm::ivec3 c(i, j, k);
        for (int a = 0; a < 3; ++a)
          for (int side = 0; side < 2; ++side) {
            glm::ivec3 q = c;
            q[a] += side ? 1 : -1;
            if (!types.inside(q.x, q.y, q.z)) {
              if (sides[2 * a + side] == Boundary::Open) s += x(i, j, k);  // air, p = 0
            } else if (types(q.x, q.y, q.z) == kFluid) {
              s += double(x(i, j, k)) - x(q.x, q.y, q.z);
            }
          }
        y[types.index(i, j, k)] = s;
      }
  return y;
}

/// |b' - A p| / |b'| in double, b' = b on fluid cells (mean-free when no side is open).
double relativeResidual(const FlagGrid& types, const Sides& sides, const ScalarGrid& b,
                        const ScalarGrid& p, bool singular) {
  double mean = 0.0, count = 0.0;
  for (std::size_t c = 0; c < b.count(); ++c)
    if (types[c] == kFluid) mean += b[c], count += 1.0;
  mean = singular ? mean / count : 0.0;
  const std::vector<double> ap = referenceOperator(types, sides, p);
  double rr = 0.0, bb = 0.0;
  for (std::size_t c = 0; c < b.count(); ++c) {
    if (types[c] != kFluid) continue;
    const double bi = b[c] - mean;
    rr += (bi - ap[c]) * (bi - ap[c]);
    bb += bi * bi;
  }
  return std::sqrt(rr / bb);
}

double norm(const ScalarGrid& a) { return std::sqrt(dot(a, a)); }

TEST(Pressure, OperatorIsSymmetric) {
  const glm::ivec3 n(20, 17, 13);
  for (Obstacle ob : {Obstacle::Sphere, Obstacle::WallBlock}) {
    const FlagGrid types = makeTypes(n, ob);
    for (const Sides& sides : {kMixed, kAllClosed, kAllOpen}) {
      PressureSolver solver;
      solver.setup(types, sides);
      // Solid cells of x and y hold garbage: the operator must ignore them.
      const ScalarGrid x = randomField(n, 1), y = randomField(n, 2);
      ScalarGrid ax, ay;
      solver.applyOperator(x, ax);
      solver.applyOperator(y, ay);
      const double xay = dot(x, ay), yax = dot(y, ax);
      EXPECT_NEAR(xay, yax, 1e-5 * std::sqrt(dot(x, x) * dot(ay, ay)));
      const std::vector<double> ref = referenceOperator(types, sides, x);
      for (std::size_t c = 0; c < types.count(); ++c) ASSERT_NEAR(ax[c], ref[c], 1e-5);
      for (std::size_t c = 0; c < types.count(); ++c)
        if (types[c] == kSolid) ASSERT_EQ(ax[c], 0.f);
    }
  }
}

TEST(Pressure, PositiveDefiniteWithAnOpenSide) {
  const glm::ivec3 n(16, 12, 10);
  const FlagGrid types = makeTypes(n, Obstacle::WallBlock);
  PressureSolver solver;
  solver.setup(types, kOpenTop);
  ScalarGrid ax;
  for (unsigned seed = 0; seed < 5; ++seed) {
    ScalarGrid x = randomField(n, seed, &types);
    solver.applyOperator(x, ax);
    EXPECT_GT(dot(x, ax), 0.0);
  }
  // The constant, the null vector of the closed box, only sees the open top: x·Ax = 16·12.
  ScalarGrid one(n, 1.f);
  for (std::size_t c = 0; c < types.count(); ++c)
    if (types[c] == kSolid) one[c] = 0.f;
  solver.applyOperator(one, ax);
  EXPECT_NEAR(dot(one, ax), double(n.x * n.y), 1e-3);
  // Closed on all sides the constant is in the null space.
  solver.setup(types, kAllClosed);
  solver.applyOperator(one, ax);
  for (std::size_t c = 0; c < ax.count(); ++c) ASSERT_EQ(ax[c], 0.f);
}

struct Case {
  const char* name;
  Sides sides;
  Obstacle obstacle;
};
const Case kCases[] = {{"all-open", kAllOpen, Obstacle::None},
                       {"all-closed", kAllClosed, Obstacle::None},
                       {"sphere,open-top", kOpenTop, Obstacle::Sphere},
                       {"wall-block,mixed", kMixed, Obstacle::WallBlock},
                       {"wall-block,closed", kAllClosed, Obstacle::WallBlock}};

bool isSingular(const Sides& s) {
  for (Boundary b : s)
    if (b == Boundary::Open) return false;
  return true;
}

/// A smooth right side (a pair of Gaussian blobs, like the divergence of a rising plume).
ScalarGrid smoothRhs(glm::ivec3 n) {
  ScalarGrid b(n);
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const glm::vec3 p = (glm::vec3(i, j, k) + 0.5f) / glm::vec3(n);
        const float g1 = std::exp(-40.f * glm::dot(p - glm::vec3(0.3f), p - glm::vec3(0.3f)));
        const float g2 = std::exp(-40.f * glm::dot(p - glm::vec3(0.7f), p - glm::vec3(0.7f)));
        b(i, j, k) = 3.f * (g1 - 0.5f * g2);
      }
  return b;
}

/// Solves and checks the residual of the returned p (in double, with the reference operator),
/// the reported residual, zero pressure on solids and the mean in the singular case. Returns
/// the statistics; `floor` is the residual that float storage of p allows (see below).
PressureStats solveAndCheck(const FlagGrid& types, const Sides& sides, const ScalarGrid& b,
                            float tol, const std::string& label) {
  const glm::ivec3 n = types.size();
  PressureSolver solver;
  solver.setup(types, sides);
  ScalarGrid p(n, 0.f);
  const PressureStats st = solver.solve(b, p, tol, 200);
  const bool singular = isSingular(sides);
  const double res = relativeResidual(types, sides, b, p, singular);
  // Rounding p to float perturbs A p by 2e-7 .. 3.4e-7 |p| (measured), so no float p has a
  // smaller residual than that; the solver stops below 5e-7 |p|/|b| (or when restarts stop
  // gaining). Random right sides have |p| ~ 1-6 |b|; smooth ones |p| ~ N² |b| / 10, for which
  // the floor (~1e-5 at 32³, ~5e-5 at 64³) is above 1e-6.
  const double floor = 1e-6 * norm(p) / norm(b);
  std::printf("  %-18s %2dx%2dx%2d tol %.0e: %2d iterations, residual %.2e (float floor %.1e)\n",
              label.c_str(), n.x, n.y, n.z, double(tol), st.iterations, res, floor);
  EXPECT_NEAR(res, st.relativeResidual, 1e-3 * res + 1e-9) << label;
  EXPECT_LE(res, std::max(1.01 * tol, floor)) << label;
  double sum = 0.0, maxAbs = 0.0;
  for (std::size_t i = 0; i < p.count(); ++i) {
    if (types[i] == kSolid) EXPECT_EQ(p[i], 0.f) << label;
    sum += p[i];
    maxAbs = std::max(maxAbs, double(std::abs(p[i])));
  }
  if (singular) EXPECT_LE(std::abs(sum) / double(p.count()), 1e-6 * maxAbs) << label;
  return st;
}

TEST(Pressure, ReachesToleranceOnAllConfigurations) {
  // Bound: the V(2,2) cycle reduces the residual ~3-5x per iteration (counts printed: 8-13 to
  // 1e-6 for random right sides, up to 19 for smooth ones, which restart CG once from the true
  // residual); 30 leaves room without hiding a loss of the multigrid rate.
  for (glm::ivec3 n : {glm::ivec3(32), glm::ivec3(64, 48, 40)})
    for (const Case& c : kCases) {
      const FlagGrid types = makeTypes(n, c.obstacle);
      for (float tol : {1e-4f, 1e-6f}) {
        const PressureStats st = solveAndCheck(types, c.sides, randomField(n, 11), tol, c.name);
        EXPECT_LE(st.iterations, 30) << c.name;
        const PressureStats sm =
            solveAndCheck(types, c.sides, smoothRhs(n), tol, std::string(c.name) + ",smooth");
        EXPECT_LE(sm.iterations, 30) << c.name;
      }
    }
}

TEST(Pressure, IterationsAreNearlyResolutionIndependent) {
  int previous = 0;
  for (int res : {16, 32, 64, 96}) {
    const glm::ivec3 n(res);
    const FlagGrid types = makeTypes(n, Obstacle::Sphere);
    const PressureStats st = solveAndCheck(types, kOpenTop, randomField(n, 5), 1e-6f, "sphere");
    EXPECT_LE(st.iterations, 30);  // see ReachesToleranceOnAllConfigurations
    // Multigrid: refining the grid adds at most a few iterations (plain CG would double them).
    if (previous) EXPECT_LE(st.iterations, previous + 4);
    previous = st.iterations;
  }
}

TEST(Pressure, ThinDomainsStillConverge) {
  // Fewer than 8 cells on an axis: coarsening continues below 4 cells on that axis.
  for (glm::ivec3 n : {glm::ivec3(96, 80, 3), glm::ivec3(5, 200, 40), glm::ivec3(1, 1, 50)}) {
    const FlagGrid types = makeTypes(n, Obstacle::None);
    const PressureStats st = solveAndCheck(types, kOpenTop, randomField(n, 3), 1e-6f, "thin");
    EXPECT_LE(st.iterations, 60);
  }
}

TEST(Pressure, RecoversAnExactSolution) {
  const glm::ivec3 n(32, 28, 24);
  for (const Case& c : kCases) {
    const FlagGrid types = makeTypes(n, c.obstacle);
    PressureSolver solver;
    solver.setup(types, c.sides);
    ScalarGrid exact = randomField(n, 21, &types);
    if (isSingular(c.sides)) {  // the solution is returned mean-free
      double mean = 0.0, count = 0.0;
      for (std::size_t i = 0; i < exact.count(); ++i)
        if (types[i] == kFluid) mean += exact[i], count += 1.0;
      for (std::size_t i = 0; i < exact.count(); ++i)
        if (types[i] == kFluid) exact[i] -= float(mean / count);
    }
    ScalarGrid b;
    solver.applyOperator(exact, b);
    ScalarGrid p(n, 0.f);
    const PressureStats st = solver.solve(b, p, 1e-6f, 200);
    double ee = 0.0, xx = 0.0;
    for (std::size_t i = 0; i < p.count(); ++i) {
      ee += double(p[i] - exact[i]) * (p[i] - exact[i]);
      xx += double(exact[i]) * exact[i];
    }
    // The error is A⁻¹ r: at most |r|/λ_min(A). For a rough p*, |b| ~ 3 |p*| and λ_min >= ~0.01
    // here, so |e|/|p*| <= 1e-6 · 3 / 0.01 = 3e-4; measured ~1e-6.
    std::printf("  exact %-18s %2d iterations, |p - p*|/|p*| = %.2e\n", c.name, st.iterations,
                std::sqrt(ee / xx));
    EXPECT_LE(std::sqrt(ee / xx), 3e-4) << c.name;
  }
}

TEST(Pressure, DeterministicForAnyThreadCount) {
  const glm::ivec3 n(48, 40, 36);
  for (const Case& c : kCases) {
    const FlagGrid types = makeTypes(n, c.obstacle);
    const ScalarGrid b = randomField(n, 8);
    ScalarGrid p1(n, 0.f), p2(n, 0.f);
    PressureStats s1, s2;
    {
      ThreadLimit limit(1);
      PressureSolver solver;
      solver.setup(types, c.sides);
      s1 = solver.solve(b, p1, 1e-6f, 200);
    }
    {
      ThreadLimit limit(2);
      PressureSolver solver;
      solver.setup(types, c.sides);
      s2 = solver.solve(b, p2, 1e-6f, 200);
    }
    EXPECT_EQ(s1.iterations, s2.iterations) << c.name;
    EXPECT_EQ(s1.relativeResidual, s2.relativeResidual) << c.name;
    EXPECT_EQ(0, std::memcmp(p1.data(), p2.data(), p1.count() * sizeof(float))) << c.name;
  }
}

TEST(Pressure, ZeroRightSideAndWarmStart) {
  const glm::ivec3 n(24, 20, 16);
  const FlagGrid types = makeTypes(n, Obstacle::Sphere);
  PressureSolver solver;
  solver.setup(types, kOpenTop);
  ScalarGrid p = randomField(n, 4);
  PressureStats st = solver.solve(ScalarGrid(n, 0.f), p, 1e-6f, 200);
  EXPECT_EQ(st.iterations, 0);
  for (std::size_t i = 0; i < p.count(); ++i) ASSERT_EQ(p[i], 0.f);
  // Closed box with a constant right side: its mean-free part is 0, so p = 0 too.
  solver.setup(types, kAllClosed);
  p = randomField(n, 4);
  st = solver.solve(ScalarGrid(n, 2.f), p, 1e-6f, 200);
  EXPECT_EQ(st.iterations, 0);
  for (std::size_t i = 0; i < p.count(); ++i) ASSERT_EQ(p[i], 0.f);
  // A converged answer as the initial guess needs no iteration.
  solver.setup(types, kOpenTop);
  const ScalarGrid b = randomField(n, 9);
  p.fill(0.f);
  const PressureStats cold = solver.solve(b, p, 1e-5f, 200);
  const PressureStats warm = solver.solve(b, p, 1e-4f, 200);
  EXPECT_GT(cold.iterations, 0);
  EXPECT_EQ(warm.iterations, 0);
  EXPECT_LE(warm.relativeResidual, 1e-4f);
}

TEST(Pressure, SetupAgainMatchesAFreshSolver) {
  // setup() reuses its buffers: after other sizes and obstacles (a moving obstacle, or a grid
  // with the same padded size but swapped axes) the result must be bit-identical to a new solver.
  const glm::ivec3 n(20, 30, 12);
  const FlagGrid sphere = makeTypes(n, Obstacle::Sphere);
  const ScalarGrid b = randomField(n, 6);
  PressureSolver reused;
  reused.setup(makeTypes(glm::ivec3(30, 20, 12), Obstacle::WallBlock), kAllClosed);
  ScalarGrid other(glm::ivec3(30, 20, 12), 0.f);
  reused.solve(randomField(glm::ivec3(30, 20, 12), 7), other, 1e-6f, 200);
  reused.setup(makeTypes(n, Obstacle::WallBlock), kOpenTop);
  ScalarGrid p1(n, 0.f), p2(n, 0.f);
  reused.solve(b, p1, 1e-6f, 200);
  reused.setup(sphere, kOpenTop);
  p1.fill(0.f);
  const PressureStats s1 = reused.solve(b, p1, 1e-6f, 200);
  PressureSolver fresh;
  fresh.setup(sphere, kOpenTop);
  const PressureStats s2 = fresh.solve(b, p2, 1e-6f, 200);
  EXPECT_EQ(s1.iterations, s2.iterations);
  EXPECT_EQ(0, std::memcmp(p1.data(), p2.data(), p1.count() * sizeof(float)));
  EXPECT_LE(relativeResidual(sphere, kOpenTop, b, p1, false), 1.01e-6);
}

TEST(Pressure, RejectsMismatchedSizes) {
  PressureSolver solver;
  ScalarGrid b(glm::ivec3(8)), p(glm::ivec3(8));
  EXPECT_THROW(solver.solve(b, p, 1e-4f, 10), std::invalid_argument);  // no setup()
  solver.setup(FlagGrid(glm::ivec3(8, 8, 9), kFluid), kOpenTop);
  EXPECT_THROW(solver.solve(b, p, 1e-4f, 10), std::invalid_argument);
  EXPECT_THROW(solver.setup(FlagGrid(glm::ivec3(0, 8, 8)), kOpenTop), std::invalid_argument);
}

}  // namespace
}  // namespace plume
