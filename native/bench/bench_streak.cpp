// Benchmark of the streak-surface pipeline (issue 4, smoke_surfaces.txt §3.3–3.4): 20 point
// sources × 300 frames, one particle per source per frame. Times what "Build Surfaces" does in the
// native core: h(α,β) over the whole shot, clustering and ordering, then for every frame the NURBS
// of every surface and its density map (k_u = 4, k_v = 2) on a 50³ density grid.
// Run: build/native/plume_bench_streak
#include "nurbs/density_map.h"
#include "nurbs/interpolation.h"
#include "streak/clustering.h"
#include "tracers/streak_frame.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

namespace plume {
namespace {

constexpr int kSources = 20;
constexpr int kFrames = 300;

/// Streaklines of an incense-like plume: the sources sit on a small ring; particles rise and
/// sway with an age-dependent phase, each source with its own phase, so that the clustering
/// finds several sheets.
std::vector<StreakFrame> syntheticShot() {
  std::vector<StreakFrame> frames(kFrames);
  for (int t = 0; t < kFrames; ++t) {
    StreakFrame& f = frames[std::size_t(t)];
    f.counts.assign(kSources, t + 1);
    f.groups.assign(kSources, 0);
    for (int s = 0; s < kSources; ++s) {
      const float phase = 6.2831853f * float(s % 5) / 5.f + 0.05f * float(s);
      const glm::vec3 base(0.5f + 0.02f * std::cos(0.314f * s), 0.5f + 0.02f * std::sin(0.314f * s),
                           0.1f);
      for (int i = 0; i <= t; ++i) {
        const float age = float(t - i);
        const float r = 0.002f * age;
        f.positions.push_back(base + glm::vec3(r * std::sin(0.05f * age + phase),
                                               r * std::cos(0.07f * age + phase), 0.003f * age));
        f.density.push_back(std::exp(-0.01f * age));
        f.outside.push_back(0);
      }
    }
  }
  return frames;
}

ScalarGrid plumeDensity(int n) {
  ScalarGrid d({n, n, n});
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const float x = (i + 0.5f) / n - 0.5f, y = (j + 0.5f) / n - 0.5f;
        d(i, j, k) = std::exp(-(x * x + y * y) / 0.01f) * (1.f - float(k) / float(n));
      }
  return d;
}

void BM_StreakClustering(benchmark::State& state) {
  const std::vector<StreakFrame> frames = syntheticShot();
  std::size_t surfaces = 0;
  for (auto _ : state) {
    const std::vector<StreakSurface> s = buildSurfaces(frames, {}, -1.0);
    surfaces = s.size();
    benchmark::DoNotOptimize(surfaces);
  }
  state.counters["surfaces"] = double(surfaces);
}

void BM_StreakPipeline(benchmark::State& state) {
  const std::vector<StreakFrame> frames = syntheticShot();
  const ScalarGrid density = plumeDensity(50);
  DensityMapParams mapParams;
  mapParams.cellSize = 1.f / 50.f;
  // The default h0 (mean of h); on this ring of sources it makes one sheet of all 20 streaklines,
  // the most expensive case for the v direction.
  const double h0 = -1.0;
  std::size_t surfaceFrames = 0, surfaceCount = 0;
  for (auto _ : state) {
    surfaceFrames = 0;
    const std::vector<StreakSurface> surfaces = buildSurfaces(frames, {}, h0);
    surfaceCount = surfaces.size();
    for (const StreakFrame& f : frames) {
      const std::vector<std::size_t> offsets = f.offsets();
      const int nu = f.counts[0];
      for (const StreakSurface& s : surfaces) {
        std::vector<glm::vec3> q;
        q.reserve(std::size_t(nu) * s.sources.size());
        for (int src : s.sources)
          q.insert(q.end(), f.positions.begin() + std::ptrdiff_t(offsets[std::size_t(src)]),
                   f.positions.begin() + std::ptrdiff_t(offsets[std::size_t(src) + 1]));
        const NurbsSurface surface = interpolateSurface(q, nu, int(s.sources.size()));
        const DensityMap map = densityMap(surface, density, mapParams);
        benchmark::DoNotOptimize(map.values.data());
        ++surfaceFrames;
      }
    }
  }
  state.counters["surfaces"] = double(surfaceCount);
  state.counters["surface_frames"] = double(surfaceFrames);
}

BENCHMARK(BM_StreakClustering)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_StreakPipeline)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace plume

BENCHMARK_MAIN();
