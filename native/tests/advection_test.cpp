// Tests of the advection machinery behind the solver's speed-ups: Euler back-traces (first order,
// Mantaflow's), the schemes against a reference built from the position-based samplers, fields
// carried together against fields carried one by one, and determinism of the new option.
#include "core/parallel.h"
#include "core/rng.h"
#include "solver/advection.h"
#include "solver/smoke_solver.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

namespace plume {
namespace {

const glm::vec3 kOffsets[4] = {kCellOffset, kFaceOffsetU, kFaceOffsetV, kFaceOffsetW};

glm::ivec3 layoutSize(const MacGrid3& v, int layout) {
  return layout == 0 ? v.cells() : v.component(layout - 1).size();
}

MacGrid3 randomVelocity(glm::ivec3 n, std::uint64_t seed) {
  Rng rng(seed);
  MacGrid3 v(n);
  for (int a = 0; a < 3; ++a)
    for (std::size_t c = 0; c < v.component(a).count(); ++c)
      v.component(a)[c] = float(rng.uniform(-3.0, 3.0));
  return v;
}

ScalarGrid randomField(glm::ivec3 size, std::uint64_t seed) {
  Rng rng(seed);
  ScalarGrid g(size);
  for (std::size_t c = 0; c < g.count(); ++c) g[c] = float(rng.uniform(0.0, 1.0));
  return g;
}

/// Rigid rotation about the z axis through cell coordinates `centre`, ω rad/s, on the faces.
MacGrid3 rotation(glm::ivec3 n, glm::vec2 centre, float omega) {
  MacGrid3 v(n);
  // u(i,j,k) sits at (i - ½, j, k), v(i,j,k) at (i, j - ½, k): u = -ω (y - cy), v = ω (x - cx).
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i <= n.x; ++i) v.u()(i, j, k) = -omega * (float(j) - centre.y);
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j <= n.y; ++j)
      for (int i = 0; i < n.x; ++i) v.v()(i, j, k) = omega * (float(i) - centre.x);
  return v;
}

/// Where semi-Lagrangian linear advection with `order` traces sample (i, j, k) of the cell grid:
/// advecting the coordinate fields x, y, z returns the traced position (trilinear sampling is
/// exact on linear fields, away from the sides).
glm::vec3 tracedCell(const MacGrid3& velocity, glm::ivec3 cell, float cells, Trace order) {
  const glm::ivec3 n = velocity.cells();
  ScalarGrid coord[3] = {ScalarGrid(n), ScalarGrid(n), ScalarGrid(n)}, out[3];
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i)
        for (int a = 0; a < 3; ++a) coord[a](i, j, k) = float(glm::ivec3(i, j, k)[a]);
  Advector advector;
  advector.reserve(coord[0].count(), 3, Advection::SemiLagrangian);
  advector.trace(velocity, n, kCellOffset, cells, 1.f, Advection::SemiLagrangian, nullptr, order);
  const Advector::Field fields[3] = {{&coord[0], &out[0], 0.f}, {&coord[1], &out[1], 0.f},
                                     {&coord[2], &out[2], 0.f}};
  advector.advect(fields, 3, Interpolation::Linear, nullptr);
  return {out[0](cell.x, cell.y, cell.z), out[1](cell.x, cell.y, cell.z),
          out[2](cell.x, cell.y, cell.z)};
}

TEST(EulerTrace, IsOneStepWithTheGridPointVelocity) {
  // A linear velocity field: the face averages at a grid point are its exact value there, so
  // the Euler trace is p - Δt/Δx u(p) with u(p) from the formula (up to float rounding).
  const glm::ivec3 n(12, 11, 10);
  MacGrid3 v(n);
  auto field = [](glm::vec3 p) {
    return glm::vec3(0.3f + 0.05f * p.y - 0.02f * p.z, -0.2f + 0.04f * p.x + 0.03f * p.z,
                     0.1f - 0.03f * p.x + 0.02f * p.y);
  };
  for (int a = 0; a < 3; ++a) {
    ScalarGrid& comp = v.component(a);
    for (int k = 0; k < comp.size().z; ++k)
      for (int j = 0; j < comp.size().y; ++j)
        for (int i = 0; i < comp.size().x; ++i) {
          glm::vec3 face(i, j, k);
          face[a] -= 0.5f;  // component a sits half a cell lower along a
          comp(i, j, k) = field(face)[a];
        }
  }
  const float cells = 2.f;  // Δt/Δx: the traces move about a cell
  for (int k = 3; k < 7; ++k)
    for (int j = 3; j < 8; ++j)
      for (int i = 3; i < 9; ++i) {
        const glm::vec3 p(i, j, k);
        const glm::vec3 expected = p - cells * field(p);
        const glm::vec3 traced = tracedCell(v, {i, j, k}, cells, Trace::Euler);
        for (int a = 0; a < 3; ++a) ASSERT_NEAR(traced[a], expected[a], 2e-5f) << i << j << k;
      }
}

TEST(EulerTrace, IsFirstOrderAndMidpointSecondOrder) {
  // In a rigid rotation the exact back-trace turns p by -ω Δt about the axis. The error of one
  // step is O(Δt²) for Euler (halving Δt divides it by 4) and O(Δt³) for the midpoint rule (8).
  const glm::ivec3 n(24, 24, 4);
  const glm::vec2 centre(11.5f, 11.5f);
  const float omega = 1.f;
  const MacGrid3 v = rotation(n, centre, omega);
  const glm::ivec3 cell(17, 11, 2);  // 5.5 cells from the axis
  auto error = [&](float dt, Trace order) {
    const glm::vec3 traced = tracedCell(v, cell, dt, order);
    const glm::vec2 r = glm::vec2(cell) - centre;
    const float c = std::cos(-omega * dt), s = std::sin(-omega * dt);
    const glm::vec2 exact = centre + glm::vec2(c * r.x - s * r.y, s * r.x + c * r.y);
    return double(glm::length(glm::vec2(traced) - exact));
  };
  const double euler1 = error(0.2f, Trace::Euler), euler2 = error(0.1f, Trace::Euler);
  const double mid1 = error(0.2f, Trace::Midpoint), mid2 = error(0.1f, Trace::Midpoint);
  EXPECT_NEAR(euler1 / euler2, 4.0, 0.4);
  EXPECT_NEAR(mid1 / mid2, 8.0, 1.0);
  EXPECT_LT(mid1, 0.2 * euler1);
}

/// What Advector gives for φ, by the textbook formulas on the position-based samplers and
/// traceBack() (midpoint traces), sample by sample.
ScalarGrid referenceAdvection(const MacGrid3& velocity, const ScalarGrid& phi, glm::vec3 offset,
                              float cells, Advection scheme, Interpolation interpolation) {
  const glm::ivec3 size = phi.size();
  auto at = [&](const ScalarGrid& g, glm::vec3 q) { return sample(g, q, interpolation); };
  auto back = [&](int i, int j, int k) {
    return traceBack(velocity, glm::vec3(i, j, k) + offset, cells) - offset;
  };
  auto fore = [&](int i, int j, int k) {
    return traceBack(velocity, glm::vec3(i, j, k) + offset, -cells) - offset;
  };
  auto each = [&](ScalarGrid& out, const auto& value) {
    out.resize(size);
    for (int k = 0; k < size.z; ++k)
      for (int j = 0; j < size.y; ++j)
        for (int i = 0; i < size.x; ++i) out(i, j, k) = value(i, j, k);
  };
  auto clamped = [&](float value, glm::vec3 q) {
    float lo, hi;
    sampleRange(phi, q, lo, hi);
    return value < lo ? lo : (value > hi ? hi : value);
  };
  ScalarGrid hat, out;
  each(hat, [&](int i, int j, int k) { return at(phi, back(i, j, k)); });
  if (scheme == Advection::SemiLagrangian) return hat;
  if (scheme == Advection::MacCormack) {
    each(out, [&](int i, int j, int k) {
      const float value = hat(i, j, k) + 0.5f * (phi(i, j, k) - at(hat, fore(i, j, k)));
      return clamped(value, back(i, j, k));
    });
    return out;
  }
  ScalarGrid corrected;
  each(corrected, [&](int i, int j, int k) {
    return phi(i, j, k) + 0.5f * (phi(i, j, k) - at(hat, fore(i, j, k)));
  });
  each(out, [&](int i, int j, int k) { return clamped(at(corrected, back(i, j, k)), back(i, j, k)); });
  return out;
}

TEST(Advector, SchemesMatchTheirDefinitionBitForBit) {
  // Split traces, fused AVX2 passes and run-by-run fields against the formulas, on every grid
  // layout (row lengths 11 and 12: full and partial runs).
  const glm::ivec3 n(11, 7, 6);
  const MacGrid3 velocity = randomVelocity(n, 21);
  const float dt = 0.4f, h = 0.5f;
  Advector advector;
  advector.reserve(velocity.u().count(), 1, Advection::Bfecc);
  for (Advection scheme : {Advection::SemiLagrangian, Advection::MacCormack, Advection::Bfecc})
    for (Interpolation interp : {Interpolation::Linear, Interpolation::MonotonicCubic})
      for (int layout = 0; layout < 4; ++layout) {
        const ScalarGrid phi = randomField(layoutSize(velocity, layout), 30 + layout);
        ScalarGrid out;
        advector.trace(velocity, phi.size(), kOffsets[layout], dt, h, scheme, nullptr);
        advector.advect(phi, out, interp, nullptr, 0.f);
        const ScalarGrid expected =
            referenceAdvection(velocity, phi, kOffsets[layout], dt / h, scheme, interp);
        for (std::size_t c = 0; c < phi.count(); ++c)
          ASSERT_EQ(out[c], expected[c]) << int(scheme) << " " << int(interp) << " " << layout
                                         << " " << c;
      }
}

TEST(Advector, FieldsCarriedTogetherMatchFieldsCarriedAlone) {
  // One advect() call for several fields shares each run's weights; the values must be those
  // of one call per field, with a block mask too (the solver's scalars).
  const glm::ivec3 n(44, 40, 38);  // blocks beyond the blob's dilation stay inactive
  const MacGrid3 velocity = randomVelocity(n, 4);
  ScalarGrid fields[3] = {ScalarGrid(n), ScalarGrid(n), ScalarGrid(n)};
  for (int f = 0; f < 3; ++f)
    for (int k = 2; k < 9; ++k)
      for (int j = 3; j < 10; ++j)
        for (int i = 1; i < 8; ++i) fields[f](i, j, k) = float(1 + f) * float(i + j * k % 5);
  BlockMask mask, other;
  mask.build(fields[0], 0.f);
  other.build(fields[2], 0.f);
  mask.merge(other);
  ASSERT_LT(mask.fill(), 1.f);  // some blocks are skipped
  for (Advection scheme : {Advection::SemiLagrangian, Advection::MacCormack, Advection::Bfecc})
    for (Interpolation interp : {Interpolation::Linear, Interpolation::MonotonicCubic})
      for (Trace order : {Trace::Midpoint, Trace::Euler}) {
        Advector advector;
        advector.reserve(fields[0].count(), 3, scheme);
        advector.trace(velocity, n, kCellOffset, 0.3f, 0.1f, scheme, &mask, order);
        ScalarGrid together[3], alone[3];
        const Advector::Field carried[3] = {{&fields[0], &together[0], 0.f},
                                            {&fields[1], &together[1], 0.5f},
                                            {&fields[2], &together[2], 0.f}};
        advector.advect(carried, 3, interp, &mask);
        for (int f = 0; f < 3; ++f) {
          advector.advect(fields[f], alone[f], interp, &mask, carried[f].background);
          ASSERT_EQ(together[f].values(), alone[f].values()) << int(scheme) << int(interp) << f;
        }
      }
}

TEST(Solver, EulerTracesGiveTheSameResultWithOneAndTwoThreads) {
  // The settings compare_mantaflow.py uses, with an obstacle and fire for every code path.
  const glm::ivec3 res(20, 22, 26);
  auto run = [&](int threads) {
    SmokeParams p;
    p.resolution = res;
    p.cellSize = 1.f / 20.f;
    p.advection = Advection::MacCormack;
    p.interpolation = Interpolation::Linear;
    p.trace = Trace::Euler;
    p.pressureTolerance = 1e-3f;
    p.threads = threads;
    p.combustion = true;
    auto solver = std::make_unique<SmokeSolver>(p);
    CellSet source, obstacle;
    for (int k = 0; k < res.z; ++k)
      for (int j = 0; j < res.y; ++j)
        for (int i = 0; i < res.x; ++i) {
          const std::uint32_t c = std::uint32_t(i + res.x * (j + res.y * k));
          const glm::vec3 x = glm::vec3(i, j, k) + 0.5f;
          if (glm::length(x - glm::vec3(9.f, 11.f, 4.f)) < 3.f) source.cells.push_back(c);
          if (glm::length(x - glm::vec3(11.f, 11.f, 15.f)) < 3.f) obstacle.cells.push_back(c);
        }
    SourceSettings s;
    s.fuel = 1.f;
    s.velocity = glm::vec3(0.1f, 0.f, 0.3f);
    solver->addSource(source, s);
    solver->addObstacle(obstacle, Slip::NoSlip);
    for (int f = 0; f < 8; ++f) solver->advanceFrame();
    return solver;
  };
  const auto a = run(1), b = run(2);
  EXPECT_GT(a->maxSpeed(), 0.05f);
  EXPECT_EQ(a->density().values(), b->density().values());
  EXPECT_EQ(a->temperature().values(), b->temperature().values());
  EXPECT_EQ(a->velocity().u().values(), b->velocity().u().values());
  EXPECT_EQ(a->velocity().w().values(), b->velocity().w().values());
}

}  // namespace
}  // namespace plume
