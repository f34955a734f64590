/// \file flowgraph_reproduction_test.cpp
/// The proof that synthesis integrates the pathlines correctly: a real fire bake
/// records its pathline groups to a file, together with the positions its RK4 integration
/// reached; a walk restricted to temporal edges (nodes 0, 1, 2, ... of the state) synthesized
/// from the file with u_ext = 0 must put every particle where the bake's integration put it.
///
/// Tolerance. The synthesizer sees the velocity along a pathline, U(t) = u(p(t), t), only at the
/// samples Δt_n apart and integrates it with the trapezoid rule (eq. 13); the recorder integrated
/// the same U(t) with RK4 on the field. The difference after age a is the quadrature error
///   |e(a)| = |Σ_{j<a} (Δt_n (U_j + U_{j+1}) / 2 - ∫_j U dt)| <= Σ_{j<a} Δt_n³ max|Ü| / 12,
/// second order in Δt_n. Ü is estimated from the samples by second differences,
/// Ü_j ≈ (U_{j+1} - 2 U_j + U_{j-1}) / Δt_n², so the bound per interval is Δt_n |Δ²U| / 12. The
/// solver's field is only piecewise smooth (linear in time between substeps, trilinear in space
/// between cells), so Ü has kinks the second differences spread out: the test allows twice the
/// estimate (the larger of the interval's two ends) plus 1e-5 m of float32 rounding. Samples
/// see those kinks only if a particle crosses at most about one cell per node step, the regime
/// of the paper (§4.1: Δt = 0.5 Δx / U); this fire reaches 4.4 m/s on 24 cells per metre, so
/// the bound is checked at 8 nodes per frame (0.9 cells per node step at the fastest). The
/// second order itself is checked by halving Δt_n (4 -> 8 nodes per frame): the largest error
/// falls by about 4. Measured: 0.032 cells at most, 0.72 of the allowed error; 0.14 cells at 4
/// nodes per frame (1.8 cells per node step), where the estimate is just exceeded (1.01).

#include "flowgraph/pathline_recorder.h"
#include "flowgraph/synthesizer.h"
#include "flowgraph/pathline_file.h"
#include "tests/flowgraph_fire.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <string>
#include <utility>

#include <unistd.h>

namespace plume {
namespace {

constexpr int kRes = 24;
constexpr int kFrames = 40;

/// A recorded fire bake: its pathline file and the integrated positions of every sample.
/// A recorded bake; its pathline file is deleted with it, so test runs leave nothing in /tmp.
struct Bake {
  std::string path;
  PathlineLayout layout;
  std::vector<std::vector<glm::vec3>> trails;  ///< per node, index group.index(p, s)

  Bake() = default;
  Bake(const Bake&) = delete;
  Bake& operator=(const Bake&) = delete;
  Bake(Bake&& o) noexcept
      : path(std::exchange(o.path, {})), layout(o.layout), trails(std::move(o.trails)) {}
  ~Bake() {
    if (!path.empty()) std::remove(path.c_str());
  }
};

Bake bakeFire(int nodesPerFrame, float lifetime, int threads, bool half, const std::string& name) {
  const SmokeParams params = testing::fireParams(kRes, threads);
  SmokeSolver solver(params);
  const CellSet burner = testing::fireBurner(kRes, 4);
  solver.addSource(burner, testing::fireFuel());
  PathlineParams pp;
  pp.nodesPerFrame = nodesPerFrame;
  pp.lifetime = lifetime;
  pp.recordPositions = true;
  Bake bake;
  // The process id keeps two test runs on one machine from sharing (and renaming) a file.
  bake.path = ::testing::TempDir() + "plume_reproduction_" + std::to_string(::getpid()) + "_" +
              name + ".bin";
  std::unique_ptr<PathlineFileWriter> writer;
  PathlineRecorder recorder(pp, params, burner,
                            [&](const PathlineGroup& g, const std::vector<glm::vec3>& trail) {
                              writer->append(g);
                              bake.trails.push_back(trail);
                            });
  PathlineFileInfo info;
  info.layout = bake.layout = recorder.layout();
  info.resolution = params.resolution;
  info.cellSize = params.cellSize;
  info.origin = params.origin;
  info.nodesPerFrame = nodesPerFrame;
  info.float16 = half;
  writer = std::make_unique<PathlineFileWriter>(bake.path, info);
  for (int f = 0; f < kFrames; ++f) EXPECT_TRUE(solver.advanceFrame(&recorder));
  writer->finish();
  // F nodes_per_frame node steps after node 0; the last L - 2 groups are still young.
  EXPECT_EQ(recorder.groupsCompleted(), kFrames * nodesPerFrame - bake.layout.samples + 2);
  return bake;
}

/// Samples from which a particle has left the domain (zero velocity, density and temperature
/// to the end, pathline_group.h); L if it never left.
int leftAt(const PathlineGroup& g, int p) {
  int s = g.layout.samples;
  while (s > 0) {
    const std::size_t i = g.index(p, s - 1);
    if (g.velocity[i] != glm::vec3(0.f) || g.density[i] != 0.f || g.temperature[i] != 0.f) break;
    --s;
  }
  return s;
}

struct Comparison {
  double maxError = 0.0;       ///< metres
  double maxOverBound = 0.0;   ///< largest error / allowed error
  double maxCellsPerStep = 0.0;  ///< fastest sample |U| Δt_n / Δx
  double maxSpeed = 0.0;         ///< fastest sample |U|, m/s
  long long compared = 0, excluded = 0;
  double sumError = 0.0;
};

/// Synthesizes the temporal walk 0, 1, 2, ... from the bake's file and compares every live
/// particle with the bake's integrated position at the same time.
Comparison reproduce(const Bake& bake) {
  const PathlineFile file = PathlineFile::open(bake.path);
  const PathlineLayout& layout = file.layout();
  const int L = layout.samples, P = layout.particles, N = file.nodeCount();
  const double dt = layout.sampleDt, cell = file.info().cellSize;
  Comparison c;
  std::vector<PathlineGroup> groups(static_cast<std::size_t>(N));
  // Allowed error per particle and age a: 2 Σ_{j<a} Δt_n max(|Δ²U_j|, |Δ²U_{j+1}|) / 12 + 1e-5 m,
  // and the sample from which the particle is outside (not compared).
  std::vector<std::vector<double>> allowed(static_cast<std::size_t>(N));
  std::vector<std::vector<int>> left(static_cast<std::size_t>(N));
  for (int k = 0; k < N; ++k) {
    PathlineGroup& g = groups[std::size_t(k)];
    file.readGroup(k, g);
    auto d2 = [&](int p, int j) {
      j = std::min(std::max(j, 1), L - 2);
      return double(glm::length(g.velocity[g.index(p, j + 1)] - 2.f * g.velocity[g.index(p, j)] +
                                g.velocity[g.index(p, j - 1)]));
    };
    allowed[std::size_t(k)].resize(layout.values());
    for (int p = 0; p < P; ++p) {
      left[std::size_t(k)].push_back(leftAt(g, p));
      double bound = 1e-5;
      for (int a = 0; a < L; ++a) {
        allowed[std::size_t(k)][g.index(p, a)] = bound;
        bound += 2.0 * dt * std::max(d2(p, a), d2(p, a + 1)) / 12.0;
        c.maxSpeed = std::max(c.maxSpeed, double(glm::length(g.velocity[g.index(p, a)])));
      }
    }
  }
  c.maxCellsPerStep = c.maxSpeed * dt / cell;
  Synthesizer synth(layout);
  SynthParticles out;
  for (int n = 0; n < N; ++n) {
    synth.step(groups[std::size_t(n)]);  // u_ext = 0
    synth.gather(out);
    for (int gi = 0; gi < synth.liveGroups(); ++gi) {
      const int e = int(synth.firstLiveStep()) + gi;
      const int age = n - e;
      const PathlineGroup& g = groups[std::size_t(e)];
      for (int p = 0; p < P; ++p) {
        if (age >= left[std::size_t(e)][std::size_t(p)]) {
          ++c.excluded;  // it left the domain: the bake froze it, the samples say nothing more
          continue;
        }
        const glm::vec3 truth = bake.trails[std::size_t(e)][g.index(p, age)];
        const double error = double(glm::length(out.positions[std::size_t(gi * P + p)] - truth));
        c.maxError = std::max(c.maxError, error);
        c.maxOverBound = std::max(c.maxOverBound, error / allowed[std::size_t(e)][g.index(p, age)]);
        c.sumError += error;
        ++c.compared;
      }
    }
  }
  return c;
}

TEST(FlowGraphReproduction, TemporalWalkReproducesTheBakedParticles) {
  const Bake coarse = bakeFire(/*nodesPerFrame=*/4, /*lifetime=*/0.5f, /*threads=*/0, false, "npf4");
  const Bake fine = bakeFire(/*nodesPerFrame=*/8, /*lifetime=*/0.5f, /*threads=*/0, false, "npf8");
  const Comparison a = reproduce(coarse), b = reproduce(fine);
  const double cell = 1.0 / kRes;
  for (const auto* c : {&a, &b})
    std::cout << "temporal walk vs bake: " << c->compared << " particle positions ("
              << c->excluded << " after leaving the domain), max error " << c->maxError / cell
              << " cells, mean " << c->sumError / double(c->compared) / cell
              << " cells, max error / allowed " << c->maxOverBound << ", fastest "
              << c->maxCellsPerStep << " cells per node step\n";
  ASSERT_GT(b.compared, 1000000);
  // The paper's regime (fine): within the quadrature bound, a small fraction of a cell.
  ASSERT_LT(b.maxCellsPerStep, 1.0);
  EXPECT_LE(b.maxOverBound, 1.0);
  EXPECT_LT(b.maxError, 0.1 * cell);
  EXPECT_LT(a.maxError, 0.25 * cell);
  // Second order: half the node step, about a quarter of the error.
  const double ratio = a.maxError / b.maxError;
  std::cout << "error ratio for half the node step: " << ratio << " (second order: 4)\n";
  EXPECT_GT(ratio, 2.8);
  // A float16 file adds at most the half rounding of the velocity integrated over a lifetime:
  // 2^-11 |U| t_max.
  const Bake half = bakeFire(4, 0.5f, 0, true, "npf4_half");
  const Comparison h = reproduce(half);
  std::cout << "float16 file: max error " << h.maxError / cell << " cells\n";
  EXPECT_LE(h.maxError, a.maxError + 0.5 * a.maxSpeed * 0x1p-11);
}

TEST(FlowGraphReproduction, RecorderIsBitIdenticalAtOneAndTwoThreads) {
  const Bake one = bakeFire(2, 0.25f, 1, false, "threads1");
  const Bake two = bakeFire(2, 0.25f, 2, false, "threads2");
  std::ifstream fa(one.path, std::ios::binary), fb(two.path, std::ios::binary);
  const std::vector<char> a((std::istreambuf_iterator<char>(fa)), std::istreambuf_iterator<char>());
  const std::vector<char> b((std::istreambuf_iterator<char>(fb)), std::istreambuf_iterator<char>());
  EXPECT_FALSE(a.empty());
  EXPECT_TRUE(a == b);
  EXPECT_EQ(one.trails, two.trails);
  // Group k starts at the seeds and its first sample sits there.
  const PathlineGroup g = PathlineFile::open(one.path).readGroup(3);
  const auto seeds = pathlineSeeds(testing::fireBurner(kRes, 4), glm::ivec3(kRes), 1.f / kRes, glm::vec3(0.f));
  EXPECT_EQ(g.start, seeds);
  for (int p = 0; p < g.layout.particles; ++p)
    EXPECT_EQ(one.trails[3][g.index(p, 0)], seeds[std::size_t(p)]);
}

}  // namespace
}  // namespace plume
