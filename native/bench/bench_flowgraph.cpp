// Benchmark of flow-graph fire synthesis ([Graph Fire Synthesis] §5.2, Table 1):
// - synthesis per step at 3,200 pathlines per node with L = 48 (budget: <= 1 ms; the paper's
//   campfire, 3,217 pathlines per node: 35 ms), with a uniform and with a field u_ext (the
//   emitted group prepared at every step), and the gather of all live particles (positions,
//   density, temperature) a frame's output needs, and the read of one node from a pathline file
//   (float32 and float16);
// - a node step of the walk (step_node) emitting a node from the cache of prepared groups (a
//   hit: O(1)) and one read from its file and prepared (a miss, no cache);
// - VDB rasterization of those ~150k particles per frame, timed separately;
// - the pathline recorder's cost per solver step of a 64³ fire bake (3,200 seeds, L = 48).
// Run: build/native/plume_bench_flowgraph
#include "bench/bench_fire_groups.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "fields/fire_raster.h"
#include "flowgraph/pathline_recorder.h"
#include "flowgraph/synthesizer.h"
#include "flowgraph/pathline_file.h"
#include "tests/flowgraph_fire.h"

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace plume {
namespace {

constexpr int kParticles = 3200;
constexpr int kSamples = 48;
constexpr float kNodeDt = 1.f / 48.f;

/// u_ext = wind + a gentle shear, evaluated per particle (the field path of eq. 13).
struct GustField final : ExternalVelocity {
  void evaluate(const glm::vec3* x, int n, double t, glm::vec3* out) const override {
    for (int m = 0; m < n; ++m)
      out[m] = glm::vec3(0.3f + 0.2f * x[m].z, 0.1f * float(std::sin(t)), 0.f);
  }
};

const std::vector<PathlineGroup>& groups() {
  static const std::vector<PathlineGroup> g = bench::fireGroups(8, kParticles, kSamples, kNodeDt);
  return g;
}

/// A synthesizer whose ring is full (L live groups: ~153,600 particles).
std::unique_ptr<Synthesizer> warmSynthesizer(int threads) {
  auto s = std::make_unique<Synthesizer>(groups()[0].layout, threads);
  for (int n = 0; n < 2 * kSamples; ++n) s->step(groups()[std::size_t(n % 8)], glm::vec3(0.2f, 0.f, 0.f));
  return s;
}

void BM_SynthesisStepUniformWind(benchmark::State& state) {
  auto s = warmSynthesizer(int(state.range(0)));
  int n = 0;
  for (auto _ : state) s->step(groups()[std::size_t(n++ % 8)], glm::vec3(0.2f, 0.f, 0.f));
  state.counters["particles"] = double(s->particleCount());
}

void BM_SynthesisStepFieldWind(benchmark::State& state) {
  auto s = warmSynthesizer(int(state.range(0)));
  const GustField field;
  int n = 0;
  for (auto _ : state) s->step(groups()[std::size_t(n++ % 8)], field);
  state.counters["particles"] = double(s->particleCount());
}

void BM_SynthesisGather(benchmark::State& state) {
  auto s = warmSynthesizer(int(state.range(0)));
  SynthParticles out;
  for (auto _ : state) {
    s->gather(out);
    benchmark::DoNotOptimize(out.positions.data());
  }
  state.counters["particles"] = double(out.size());
}

/// The 8 groups in a pathline file (removed at exit); half: float16 samples.
class BenchFile {
 public:
  explicit BenchFile(bool half)
      : mPath(std::string("/tmp/plume_bench_pathlines") + (half ? "16" : "32") + "_" +
              std::to_string(::getpid()) + ".bin") {
    PathlineFileInfo info;
    info.layout = groups()[0].layout;
    info.resolution = glm::ivec3(128, 64, 64);
    info.cellSize = 1.f / 64.f;
    info.float16 = half;
    PathlineFileWriter w(mPath, info);
    for (const PathlineGroup& g : groups()) w.append(g);
    w.finish();
    mFile = std::make_unique<PathlineFile>(PathlineFile::open(mPath));
  }
  ~BenchFile() { std::remove(mPath.c_str()); }
  const PathlineFile& file() const { return *mFile; }

 private:
  std::string mPath;
  std::unique_ptr<PathlineFile> mFile;
};

/// Reading one node from a pathline file (a cache miss of the synthesis): the block read, its
/// checksum and the decoding; Arg: 0 float32, 1 float16.
void BM_PathlineReadGroup(benchmark::State& state) {
  const BenchFile bench(state.range(0) != 0);
  PathlineGroup g;
  int k = 0;
  for (auto _ : state) bench.file().readGroup(k++ % 8, g);
  state.counters["bytes_per_node"] = double(bench.file().bytesPerNode());
}

/// One node step of the walk, step_node() on a full ring with a uniform wind, cycling over the
/// 8 nodes of a float32 file. Args: threads (0: all), cache: 1 every node is in the cache of
/// prepared groups (hits: nothing read, nothing copied), 0 no cache (every step reads its node
/// from the file and prepares it).
void BM_SynthesisStepNode(benchmark::State& state) {
  const BenchFile bench(false);
  const bool cached = state.range(1) != 0;
  Synthesizer s(groups()[0].layout, int(state.range(0)), cached ? std::size_t(1) << 30 : 0);
  int n = 0;
  for (; n < 2 * kSamples; ++n) s.stepNode(bench.file(), n % 8, 0, glm::vec3(0.2f, 0.f, 0.f));
  const long long misses = s.cache().misses(), hits = s.cache().hits();
  for (auto _ : state) s.stepNode(bench.file(), n++ % 8, 0, glm::vec3(0.2f, 0.f, 0.f));
  state.counters["particles"] = double(s.particleCount());
  state.counters["hit_share"] = double(s.cache().hits() - hits) /
                                double(s.cache().hits() - hits + s.cache().misses() - misses);
}

/// One synthesized frame rasterized (fields/fire_raster.h). Args: threads (0: all), sheets: 1
/// as the synthesis does it (velocities, splats also spanning the node step's gap |u| Δt_n),
/// 0 the particles alone (splats from the spacing only).
void BM_FireRasterFrame(benchmark::State& state) {
  auto s = warmSynthesizer(0);
  SynthParticles out;
  s->gather(out);
  FireRasterParams p;
  p.voxelSize = 1.f / 48.f;  // the particles fill about 1 x 1 x 2.5 m: 48 x 48 x 120 voxels
  p.threads = int(state.range(0));
  const bool sheets = state.range(1) != 0;
  if (sheets) p.sheetInterval = kNodeDt;
  std::size_t voxels = 0;
  for (auto _ : state) {
    const FireGrids g = rasterizeFire({out.positions.data(), out.density.data(), out.temperature.data(), out.size(),
                                       sheets ? out.velocity.data() : nullptr},
                                      p);
    voxels = g.density->activeVoxelCount();
  }
  state.counters["particles"] = double(out.size());
  state.counters["voxels"] = double(voxels);
}

/// Times the recorder's share of every step it follows.
class TimedRecorder final : public StepObserver {
 public:
  explicit TimedRecorder(PathlineRecorder& r) : mRecorder(r) {}
  void beforeStep(const SmokeSolver& s) override { timed([&] { mRecorder.beforeStep(s); }); }
  void afterStep(const SmokeSolver& s, float dt) override {
    timed([&] { mRecorder.afterStep(s, dt); });
    ++steps;
  }
  double seconds = 0.0;
  int steps = 0;

 private:
  template <typename F>
  void timed(const F& f) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  PathlineRecorder& mRecorder;
};

void BM_RecorderPerSolverStep64(benchmark::State& state) {
  // 64³ fire with a burner of 20 x 10 x 2 cells: 400 cells, the 3,200 seeds of the synthesis budget.
  const int n = 64;
  const SmokeParams params = testing::fireParams(n, int(state.range(0)));
  SmokeSolver solver(params);
  CellSet burner;
  for (int k = 1; k < 3; ++k)
    for (int j = 27; j < 37; ++j)
      for (int i = 22; i < 42; ++i) burner.cells.push_back(std::uint32_t(i + n * (j + n * k)));
  solver.addSource(burner, testing::fireFuel());
  PathlineParams pp;  // 2 nodes per frame, 1 s: L = 48
  long long completed = 0;
  PathlineRecorder recorder(pp, params, burner,
                            [&](const PathlineGroup&, const std::vector<glm::vec3>&) { ++completed; });
  TimedRecorder timed(recorder);
  // Fill the recorder: L groups alive after L / nodes_per_frame frames.
  for (int f = 0; f < 26; ++f) solver.advanceFrame(&timed);
  timed.seconds = 0.0;
  timed.steps = 0;
  double total = 0.0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    solver.advanceFrame(&timed);
    total += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  const double steps = double(timed.steps);
  state.counters["seeds"] = double(recorder.layout().particles);
  state.counters["live_particles"] = double(recorder.layout().particles) * recorder.layout().samples;
  state.counters["recorder_ms_per_step"] = 1e3 * timed.seconds / steps;
  state.counters["solver_ms_per_step"] = 1e3 * (total - timed.seconds) / steps;
  state.counters["recorder_share"] = timed.seconds / (total - timed.seconds);
  state.counters["steps_per_frame"] = steps / double(state.iterations());
  benchmark::DoNotOptimize(completed);
}

}  // namespace
}  // namespace plume

BENCHMARK(plume::BM_SynthesisStepUniformWind)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(plume::BM_SynthesisStepFieldWind)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(plume::BM_SynthesisGather)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(plume::BM_SynthesisStepNode)
    ->ArgNames({"threads", "cache"})->Args({1, 1})->Args({1, 0})->Args({0, 1})->Args({0, 0})
    ->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(plume::BM_PathlineReadGroup)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(plume::BM_FireRasterFrame)
    ->Args({1, 0})
    ->Args({0, 0})
    ->Args({1, 1})
    ->Args({0, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(plume::BM_RecorderPerSolverStep64)->Arg(1)->Arg(0)->Iterations(6)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();
