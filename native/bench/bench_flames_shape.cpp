// Benchmark of the shape stage of structural flames ([Structural Flames] §4.4–4.5, §5):
// sampling, flow noise, spine mapping, Kolmogorov noise, merging, incandescence for one frame of
// the torch (5 flames × 9,000 particles; budget ≤ 10 ms per frame including structure; the
// paper: 2.7 s) and of the dragon breath (80 flames, 1.5 M particles, merging off as in the
// paper; budget ≤ 0.5 s; the paper: 34 s). Rasterization into VDB grids is timed separately.
// Time: wall (real_time), CPU of the calling thread (Time's CPU column) and of the whole process
// (counter proc_cpu_ms, all threads). *Shape reuses the frame's arrays as a bake's frame loop does
// (one untimed warm-up frame first); *ShapeCold starts each frame from empty arrays (first-touch
// allocation included). On a shared machine take the minimum of repetitions:
// BM_TorchFrame is the torch's whole per-frame budget in one loop: one structure step of the torch
// of plume_bench_flames (FlameSystem, after 48 warm-up frames) plus the shape of the 5 flames
// above, both limited to the argument's thread count (1: one core).
// Run: build/native/plume_bench_flames_shape --benchmark_repetitions=5
#include "core/parallel.h"
#include "core/rng.h"
#include "flames/flame_raster.h"
#include "flames/flame_shape.h"
#include "tests/flames_scenes.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <ctime>
#include <vector>

namespace plume {
namespace {

/// A flame of n points rising from `base` over `length`, bent sideways by `lean`.
Flame benchFlame(glm::dvec3 base, double length, double lean, double radius, std::uint32_t id) {
  Flame f;
  f.id = id;
  f.radius = radius;
  const int n = 10;
  for (int k = 0; k < n; ++k) {
    const double s = double(k) / (n - 1);
    SpinePoint p;
    p.x = base + glm::dvec3(lean * s * s, 0.3 * lean * s, length * s);
    p.v = {2.0 * lean * s, 0.0, 1.0};
    p.age = s * length;
    f.points.push_back(p);
  }
  return f;
}

std::vector<Flame> torchFlames() {
  std::vector<Flame> flames;
  for (int f = 0; f < 5; ++f) {
    const double a = 2.0 * 3.14159265 * f / 5.0;
    flames.push_back(benchFlame({0.03 * std::cos(a), 0.03 * std::sin(a), 0.0}, 0.3, 0.05 * std::cos(a), 0.03,
                                std::uint32_t(f + 1)));
  }
  return flames;
}

std::vector<Flame> dragonFlames() {
  std::vector<Flame> flames;
  Rng rng(5);
  for (int f = 0; f < 80; ++f)
    flames.push_back(benchFlame({rng.uniform(0.0, 2.0), rng.uniform(-0.4, 0.4), rng.uniform(0.0, 0.6)},
                                rng.uniform(0.4, 0.9), rng.uniform(-0.3, 0.3), 0.1, std::uint32_t(f + 1)));
  return flames;
}

FlameShapeParams torchParams(int threads) {
  FlameShapeParams p;
  p.sampling.fixedCount = 9000;
  p.threads = threads;
  return p;
}

FlameShapeParams dragonParams(int threads) {
  FlameShapeParams p;
  p.sampling.fixedCount = 1500000 / 80;
  p.merging = false;
  p.kolmogorov.scale = 2.0;
  p.kolmogorov.amplitude = 0.05;
  p.threads = threads;
  return p;
}

FlameCamera benchCamera() {
  FlameCamera c;
  c.position = {1.0, -4.0, 0.8};
  return c;
}

/// CPU seconds of all the process's threads.
double processCpu() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

void runShape(benchmark::State& state, const std::vector<Flame>& flames, const FlameShapeParams& params,
              ProfileShape shape, bool cold) {
  const FlameShaper shaper({FlameProfile::library(shape)}, params);
  const FlameCamera camera = benchCamera();
  double t = 0.0, cpu = 0.0;
  std::size_t particles = 0;
  FlameShapeFrame frame;  // reused, as in a bake's frame loop
  if (!cold) shaper.shape(flames, t, camera, frame);
  for (auto _ : state) {
    if (cold) {
      state.PauseTiming();
      frame = FlameShapeFrame{};
      state.ResumeTiming();
    }
    const double start = processCpu();
    shaper.shape(flames, t, camera, frame);
    cpu += processCpu() - start;
    particles = frame.particles.size();
    benchmark::DoNotOptimize(frame.particles.positions.data());
    t += 1.0 / 24.0;
  }
  state.counters["particles"] = double(particles);
  state.counters["proc_cpu_ms"] = 1e3 * cpu / double(state.iterations());
}

void runRaster(benchmark::State& state, const std::vector<Flame>& flames, const FlameShapeParams& params,
               ProfileShape shape, float voxel) {
  const FlameShaper shaper({FlameProfile::library(shape)}, params);
  const FlameShapeFrame frame = shaper.shape(flames, 0.5, benchCamera());
  FlameRasterParams raster;
  raster.voxelSize = voxel;
  raster.threads = params.threads;
  std::size_t voxels = 0;
  for (auto _ : state) {
    const FlameGrids grids = rasterizeFlames(frame.particles, raster);
    voxels = grids.density->activeVoxelCount();
  }
  state.counters["voxels"] = double(voxels);
}

/// Structure step + shape per frame with `threads` threads (ThreadLimit covers the step; the
/// shaper applies its own params.threads).
void BM_TorchFrame(benchmark::State& state) {
  const int threads = int(state.range(0));
  ThreadLimit limit(threads);
  FlameSystem system = testing::torchFlames(1, 16);
  for (int i = 0; i < 48; ++i) system.step(1.0 / 24.0);
  const std::vector<Flame> flames = torchFlames();
  const FlameShaper shaper({FlameProfile::library(ProfileShape::Torch)}, torchParams(threads));
  const FlameCamera camera = benchCamera();
  FlameShapeFrame frame;
  double t = 0.0;
  shaper.shape(flames, t, camera, frame);
  for (auto _ : state) {
    system.step(1.0 / 24.0);
    shaper.shape(flames, t, camera, frame);
    benchmark::DoNotOptimize(frame.particles.positions.data());
    t += 1.0 / 24.0;
  }
  state.counters["particles"] = double(frame.particles.size());
}

void BM_TorchShape(benchmark::State& state) {
  runShape(state, torchFlames(), torchParams(int(state.range(0))), ProfileShape::Torch, false);
}
void BM_DragonShape(benchmark::State& state) {
  runShape(state, dragonFlames(), dragonParams(int(state.range(0))), ProfileShape::Campfire, false);
}
void BM_DragonShapeCold(benchmark::State& state) {
  runShape(state, dragonFlames(), dragonParams(int(state.range(0))), ProfileShape::Campfire, true);
}
void BM_TorchRaster(benchmark::State& state) {
  runRaster(state, torchFlames(), torchParams(int(state.range(0))), ProfileShape::Torch, 0.005f);
}
void BM_DragonRaster(benchmark::State& state) {
  runRaster(state, dragonFlames(), dragonParams(int(state.range(0))), ProfileShape::Campfire, 0.02f);
}

BENCHMARK(BM_TorchFrame)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TorchShape)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DragonShape)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_DragonShapeCold)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_TorchRaster)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DragonRaster)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace plume

BENCHMARK_MAIN();
