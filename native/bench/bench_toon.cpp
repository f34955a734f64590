// Benchmark of the toon pipeline ([Cartoon Smoke]): the particle update of one frame for 10^5
// particles (budget: <= 5 ms), with and without the birth spacing, and the depth-differences
// filter at 1920x1080 (budget: <= 1 ms).
// Run: build/native/plume_bench_toon
#include "tests/toon_plume.h"
#include "toon/depth_differences.h"
#include "toon/toon_particles.h"
#include "core/parallel.h"
#include "core/rng.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

namespace plume {
namespace {

constexpr int kParticles = 100000;

/// 10^5 particles spread over the dense core of a 48x48x96 plume (cell 5 cm), full size.
ToonParticles plumeParticles(const GridFrame& g, ToonIntegration integration, int threads) {
  ToonParams p;
  p.threads = threads;
  p.birthDensity = 0.5f;
  p.birthSpacing = 0.f;  // the paper's birth rule (BM_ToonParticleUpdateBirthSpacing: σ > 0)
  p.deathDensity = 0.05f;
  p.maxCount = kParticles;
  p.integration = integration;
  ToonParticles t(p, g);
  ToonParticleState s;
  s.resize(kParticles);
  Rng rng(1);
  const glm::vec3 box = glm::vec3(g.resolution) * g.cellSize;
  for (int n = 0; n < kParticles; ++n) {
    // Within two σ of the axis, in the lower 80% of the column.
    const float r = 0.4f * box.x * float(std::sqrt(rng.uniform())), a = 6.2831853f * float(rng.uniform());
    s.positions[std::size_t(n)] = glm::vec3(0.5f * box.x + r * std::cos(a), 0.5f * box.y + r * std::sin(a),
                                            0.8f * box.z * float(rng.uniform()));
    s.ids[std::size_t(n)] = std::uint64_t(n);
    s.size[std::size_t(n)] = s.targetSize[std::size_t(n)] = p.sizeHigh;
  }
  s.nextId = kParticles;
  t.setState(s);
  return t;
}

void particleUpdate(benchmark::State& state, ToonIntegration integration) {
  const GridFrame g = testing::plumeGrid(48, 0.05f);
  const ToonFields a = testing::plumeFields(g, 1.f), b = testing::plumeFields(g, 1.f, 0.35f);
  const ToonSources sources = testing::plumeSources(g);
  // Arg: worker threads (1 gives the cost of one core; 0 = all cores).
  ToonParticles t = plumeParticles(g, integration, int(state.range(0)));
  int substeps = 0;
  for (auto _ : state) substeps = t.advanceFrame(a, b, 1.f / 24.f, sources);
  state.counters["particles"] = double(t.count());
  state.counters["substeps"] = substeps;
}

/// The same frame with room for births (budget 2·10^5), at birth spacing σ = range(0) / 10:
/// every frame starts from the same 10^5 particles, so each iteration does the same births.
void BM_ToonParticleUpdateBirthSpacing(benchmark::State& state) {
  const GridFrame g = testing::plumeGrid(48, 0.05f);
  const ToonFields a = testing::plumeFields(g, 1.f), b = testing::plumeFields(g, 1.f, 0.35f);
  const ToonSources sources = testing::plumeSources(g);
  ToonParticles full = plumeParticles(g, ToonIntegration::Euler, int(state.range(1)));
  ToonParams p = full.params();
  p.maxCount = 2 * kParticles;
  p.birthSpacing = 0.1f * float(state.range(0));
  ToonParticles t(p, g);
  std::size_t born = 0;
  for (auto _ : state) {
    state.PauseTiming();
    t.setState(full.state());
    state.ResumeTiming();
    t.advanceFrame(a, b, 1.f / 24.f, sources);
    born = t.count() - full.count();
  }
  state.counters["born"] = double(born);
}

void BM_ToonParticleUpdateEuler(benchmark::State& state) { particleUpdate(state, ToonIntegration::Euler); }
void BM_ToonParticleUpdateMidpoint(benchmark::State& state) {
  particleUpdate(state, ToonIntegration::Midpoint);
}

/// A 1920x1080 depth pass: overlapping discs at random depths on an infinite background.
std::vector<float> depthPass(int w, int h) {
  std::vector<float> z(std::size_t(w) * h, INFINITY);
  Rng rng(2);
  for (int d = 0; d < 3000; ++d) {
    const int cx = int(rng.uniform() * w), cy = int(rng.uniform() * h), r = 8 + int(rng.uniform() * 40);
    const float depth = 2.f + 8.f * float(rng.uniform());
    for (int j = std::max(0, cy - r); j < std::min(h, cy + r); ++j)
      for (int i = std::max(0, cx - r); i < std::min(w, cx + r); ++i)
        if ((i - cx) * (i - cx) + (j - cy) * (j - cy) < r * r)
          z[std::size_t(j) * w + i] = std::min(z[std::size_t(j) * w + i], depth);
  }
  return z;
}

void BM_DepthDifferences1080p(benchmark::State& state) {
  const int w = 1920, h = 1080;
  const std::vector<float> z = depthPass(w, h);
  std::vector<std::uint8_t> out(z.size());
  DepthDifferenceParams p;
  p.gamma = 0.5f;
  p.ignoreBackground = state.range(0) != 0;
  ThreadLimit limit(int(state.range(1)));  // 1: the cost of one core; 0: all cores
  for (auto _ : state) {
    depthDifferences(z.data(), w, h, p, out.data());
    benchmark::DoNotOptimize(out.data());
  }
  std::size_t outline = 0;
  for (std::uint8_t o : out) outline += o;
  state.counters["outline_fraction"] = double(outline) / double(out.size());
}

}  // namespace
}  // namespace plume

BENCHMARK(plume::BM_ToonParticleUpdateEuler)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(plume::BM_ToonParticleUpdateMidpoint)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(plume::BM_ToonParticleUpdateBirthSpacing)->ArgsProduct({{0, 5}, {1, 0}})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(plume::BM_DepthDifferences1080p)->ArgsProduct({{0, 1}, {1, 0}})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();
