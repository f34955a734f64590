/// \file bench_adaptive.cpp
/// Google Benchmark of the adaptive domain (adaptive_domain.h): the first 60 frames of the plume
/// scene of bench_solver.cpp (Plume's defaults, a 0.12 m hot sphere near the closed floor of a
/// 1 m domain with open sides) baked on the full domain and with the adaptive domain on, one
/// bake per row. Prints "ratio: X" (full-domain time / adaptive time) per resolution at the end.
/// Not a test: run build/native/plume_bench_adaptive by hand, e.g.
/// --benchmark_filter='BM_Bake60/128'.

#include "solver/emitters.h"
#include "solver/smoke_solver.h"

#include "tests/test_meshes.h"

#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <utility>

namespace plume {
namespace {

constexpr int kFrames = 60;

/// Seconds of the last bake per (resolution, adaptive).
std::map<std::pair<int, bool>, double>& bakeSeconds() {
  static std::map<std::pair<int, bool>, double> seconds;
  return seconds;
}

SmokeParams sceneParams(int n, bool adaptive) {
  SmokeParams p;
  p.resolution = glm::ivec3(n);
  p.cellSize = 1.f / float(n);
  p.vorticity = 0.3f;
  p.alpha = 1.f;
  p.beta = 1.f;
  p.boundaries = {Boundary::Open, Boundary::Open,   Boundary::Open,
                  Boundary::Open, Boundary::Closed, Boundary::Open};
  p.adaptiveDomain = adaptive;
  return p;
}

void BM_Bake60(benchmark::State& state) {
  const int n = int(state.range(0));
  const bool adaptive = state.range(1) != 0;
  double seconds = 0.0, boxShare = 0.0;
  int substeps = 0;
  for (auto _ : state) {
    SmokeSolver solver(sceneParams(n, adaptive));
    SourceSettings settings;
    settings.density = 1.f;
    settings.temperature = 2.f;
    solver.addSource(voxelizeSource(sphereMesh({0.5f, 0.5f, 0.15f}, 0.12f, 16, 32, "source"),
                                    solver.gridFrame()),
                     settings);
    const auto start = std::chrono::steady_clock::now();
    boxShare = 0.0;
    substeps = 0;
    for (int f = 0; f < kFrames; ++f) {
      solver.advanceFrame();
      const glm::ivec3 b = solver.activeBox().size();
      boxShare += double(b.x) * b.y * b.z / (double(n) * n * n) / kFrames;
      substeps += solver.lastStats().substeps;
    }
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  bakeSeconds()[{n, adaptive}] = seconds;
  state.counters["s_per_frame"] = seconds / kFrames;
  state.counters["box_share"] = boxShare;  ///< mean box cells / domain cells
  state.counters["substeps"] = substeps;
}

BENCHMARK(BM_Bake60)
    ->Args({64, 0})->Args({64, 1})->Args({128, 0})->Args({128, 1})
    ->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace
}  // namespace plume

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  for (const auto& [key, full] : plume::bakeSeconds()) {
    if (key.second) continue;
    auto adaptive = plume::bakeSeconds().find({key.first, true});
    if (adaptive == plume::bakeSeconds().end()) continue;
    std::printf("%d^3, %d frames: full %.2f s, adaptive %.2f s\nratio: %.2f\n", key.first,
                plume::kFrames, full, adaptive->second, full / adaptive->second);
  }
  return 0;
}
