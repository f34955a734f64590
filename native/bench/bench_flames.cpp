// Benchmark of the structure of structural flames ([Structural Flames] §7): one step of
// FlameSystem (evolution by eq. 1, spine fitting and re-sampling, breakaway, obstacles none) for
// the torch of Figure 1 (5 flames, n = 16; the paper: 0.2 s "dynamic simulation" + part of the
// 2.0 s "B-spline fitting" per frame) and the dragon breath of Figure 5 (5 flames split into 80+;
// the paper: 3 s + part of 1 min per frame). Shape, sampling and rasterization are timed by
// plume_bench_flames_shape.
// Run: build/native/plume_bench_flames
#include "core/parallel.h"
#include "tests/flames_scenes.h"

#include <benchmark/benchmark.h>

namespace plume {
namespace {

constexpr double kDt = 1.0 / 24.0;

/// Times step() once the scene has developed (warm-up frames), with `threads` threads.
void stepScene(benchmark::State& state, FlameSystem system, int warmup) {
  ThreadLimit limit(int(state.range(0)));
  for (int i = 0; i < warmup; ++i) system.step(kDt);
  double flames = 0.0, points = 0.0, frames = 0.0;
  for (auto _ : state) {
    system.step(kDt);
    flames += double(system.flames().size());
    for (const Flame& f : system.flames()) points += double(f.points.size());
    frames += 1.0;
  }
  state.counters["flames"] = flames / frames;
  state.counters["points"] = points / frames;
}

void torchStep(benchmark::State& state) { stepScene(state, testing::torchFlames(1, 16), 48); }
/// The torch without the spine's Kolmogorov noise (§4.2): the cost of v_K is the difference.
void torchStepWithoutSpineNoise(benchmark::State& state) {
  FlameSystem system = testing::torchFlames(1, 16);
  FlameParams p = system.params();
  p.spineNoise.amplitude = 0.0;
  system.setParams(p);
  stepScene(state, std::move(system), 48);
}
void dragonStep(benchmark::State& state) { stepScene(state, testing::dragonFlames(1, 16), 72); }

BENCHMARK(torchStep)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);
BENCHMARK(torchStepWithoutSpineNoise)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);
BENCHMARK(dragonStep)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace plume

BENCHMARK_MAIN();
