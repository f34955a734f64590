/// \file bench_solver.cpp
/// Google Benchmark of the smoke solver: whole steps, each stage of step(), and VDB output, on a
/// warmed-up plume (vorticity confinement, buoyancy, spherical source on a closed floor, open
/// sides) in two configurations: Plume's defaults (BFECC + monotonic cubic, midpoint traces,
/// pressure tolerance 1e-4) and Mantaflow's (MacCormack + trilinear, first-order Euler traces
/// from the grid-point velocity, tolerance 1e-3; the "Comparable" benchmarks, see
/// examples/smoke/compare_mantaflow.py). Not a test: run build/native/plume_bench by hand.
///
/// Memory: peak_rss_MB is the peak of the whole process so far, so it includes every solver an
/// earlier benchmark of the same run built (they are cached). For the peak of one solver, run one
/// size per process, e.g. plume_bench --benchmark_filter='BM_Step/128'; rss_MB is the resident
/// set when the benchmark ends.

#include "io/vdb_frame.h"
#include "solver/emitters.h"
#include "solver/smoke_solver.h"

#include "tests/test_meshes.h"

#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <tuple>
#include <memory>
#include <utility>

namespace plume {
namespace {

constexpr int kWarmupSteps = 4;

/// Peak resident set of the process so far, MB (Linux reports ru_maxrss in kB).
double peakRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) / 1024.0;
}

/// Resident set of the process now, MB (second field of /proc/self/statm, in pages).
double rssMb() {
  long pages = 0, resident = 0;
  if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return double(resident) * double(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

/// UV sphere of radius r around c: the source mesh.
EmitterMesh sphere(glm::vec3 c, float r) { return sphereMesh(c, r, 16, 32, "bench source"); }

/// What the benchmarks vary: the advection settings and the pressure tolerance.
struct Config {
  Advection scheme;
  Interpolation interpolation;
  Trace trace;
  float tolerance;
  bool linearVelocity = true;  ///< SmokeParams::linearVelocity (Fast Velocity)
  float turbulence = 0.f;      ///< SmokeParams::turbulence, m/s² (over 0.4 m swirls)
  bool operator<(const Config& o) const {
    return std::tie(scheme, interpolation, trace, tolerance, linearVelocity, turbulence) <
           std::tie(o.scheme, o.interpolation, o.trace, o.tolerance, o.linearVelocity,
                    o.turbulence);
  }
};
/// Plume's defaults.
constexpr Config kBfecc{Advection::Bfecc, Interpolation::MonotonicCubic, Trace::Midpoint, 1e-4f,
                        true};
/// The defaults without Fast Velocity: the velocity carried with cubic BFECC too.
constexpr Config kCubicVelocity{Advection::Bfecc, Interpolation::MonotonicCubic, Trace::Midpoint,
                                1e-4f, false};
/// The add-on's smoke defaults: Plume's defaults with Turbulence 2 m/s² over 0.4 m.
constexpr Config kTurbulent{Advection::Bfecc, Interpolation::MonotonicCubic, Trace::Midpoint,
                            1e-4f, true, 2.f};
constexpr Config kMacCormack{Advection::MacCormack, Interpolation::MonotonicCubic,
                             Trace::Midpoint, 1e-4f};
/// Mantaflow's gas solver: MacCormack with trilinear sampling and Euler traces (advection.cpp,
/// orderSpace 1, orderTrace 1), pressure accuracy 1e-3.
constexpr Config kComparable{Advection::MacCormack, Interpolation::Linear, Trace::Euler, 1e-3f};

SmokeParams benchParams(int n, bool fire, const Config& config) {
  SmokeParams p;
  p.resolution = glm::ivec3(n);
  p.cellSize = 1.f / float(n);
  p.advection = config.scheme;
  p.interpolation = config.interpolation;
  p.trace = config.trace;
  p.pressureTolerance = config.tolerance;
  p.linearVelocity = config.linearVelocity;
  p.vorticity = 0.3f;
  p.alpha = 1.f;
  p.beta = 1.f;
  p.boundaries = {Boundary::Open, Boundary::Open,   Boundary::Open,
                  Boundary::Open, Boundary::Closed, Boundary::Open};
  p.combustion = fire;
  p.turbulence = config.turbulence;
  p.turbulenceScale = 0.4f;
  return p;
}

/// One warmed-up solver per (resolution, fire), built once: Google Benchmark calls each
/// benchmark function several times while it sizes the iteration count.
SmokeSolver& warmSolver(int n, bool fire, const Config& config = kBfecc) {
  static std::map<std::tuple<int, bool, Config>, std::unique_ptr<SmokeSolver>> cache;
  auto& slot = cache[{n, fire, config}];
  if (!slot) {
    slot = std::make_unique<SmokeSolver>(benchParams(n, fire, config));
    SourceSettings settings;
    settings.density = 1.f;
    settings.temperature = 2.f;
    settings.fuel = fire ? 1.f : 0.f;
    const CellSet cells = voxelizeSource(sphere({0.5f, 0.5f, 0.15f}, 0.12f), slot->gridFrame());
    slot->addSource(cells, settings);
    const float dt = slot->params().frameDt;
    for (int s = 0; s < kWarmupSteps; ++s) slot->step(dt);
  }
  return *slot;
}

/// Everything a stage reads or writes, to run the same stage again from the same input.
struct Snapshot {
  MacGrid3 velocity;
  ScalarGrid density, temperature, fuel, soot, flame, pressure;
  explicit Snapshot(const SmokeSolver& s)
      : velocity(s.velocity()), density(s.density()), temperature(s.temperature()),
        fuel(s.fuel()), soot(s.soot()), flame(s.flame()), pressure(s.pressure()) {}
  void restore(SmokeSolver& s) const {
    s.velocity() = velocity;
    s.density() = density;
    s.temperature() = temperature;
    s.fuel() = fuel;
    s.soot() = soot;
    s.flame() = flame;
    s.pressure() = pressure;
  }
};

void stepBenchmark(benchmark::State& state, const Config& config) {
  SmokeSolver& solver = warmSolver(int(state.range(0)), /*fire=*/false, config);
  const float dt = solver.params().frameDt;
  double iterations = 0.0;
  for (auto _ : state) {
    solver.step(dt);
    iterations += solver.lastStats().pressureIterations;
  }
  state.counters["steps_per_s"] = benchmark::Counter(double(state.iterations()),
                                                     benchmark::Counter::kIsRate);
  state.counters["pressure_iters"] = iterations / double(state.iterations());
  state.counters["peak_rss_MB"] = peakRssMb();
  state.counters["rss_MB"] = rssMb();
}

void BM_Step(benchmark::State& state) { stepBenchmark(state, kBfecc); }
/// The same step with MacCormack advection (Selle et al. 2008): two interpolation passes a field.
void BM_StepMacCormack(benchmark::State& state) { stepBenchmark(state, kMacCormack); }
/// The default step with Fast Velocity off (kCubicVelocity).
void BM_StepCubicVelocity(benchmark::State& state) { stepBenchmark(state, kCubicVelocity); }
/// The default step with the add-on's Turbulence (kTurbulent).
void BM_StepTurbulence(benchmark::State& state) { stepBenchmark(state, kTurbulent); }
/// The step with Mantaflow's settings (kComparable).
void BM_StepComparable(benchmark::State& state) { stepBenchmark(state, kComparable); }
BENCHMARK(BM_Step)->Arg(50)->Arg(64)->Arg(128)->Arg(256)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_StepCubicVelocity)->Arg(64)->Arg(128)->Arg(256)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_StepTurbulence)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_StepMacCormack)->Arg(50)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond)->UseRealTime();
/// With Mantaflow's settings one step is one frame: at 256³ this row is the time per frame (VDB
/// writing excluded); run it alone for its peak_rss_MB.
BENCHMARK(BM_StepComparable)->Arg(50)->Arg(64)->Arg(128)->Arg(256)->Unit(benchmark::kMillisecond)->UseRealTime();

/// A whole frame with Plume's defaults: as many steps as the CFL number 4 asks for
/// (SmokeParams::useCfl), counted in substeps.
void frameBenchmark(benchmark::State& state, const Config& config) {
  SmokeSolver& solver = warmSolver(int(state.range(0)), /*fire=*/false, config);
  double substeps = 0.0;
  for (auto _ : state) {
    solver.advanceFrame();
    substeps += solver.lastStats().substeps;
  }
  state.counters["substeps"] = substeps / double(state.iterations());
  state.counters["peak_rss_MB"] = peakRssMb();
  state.counters["rss_MB"] = rssMb();
}
void BM_FrameDefaults(benchmark::State& state) { frameBenchmark(state, kBfecc); }
void BM_FrameCubicVelocity(benchmark::State& state) { frameBenchmark(state, kCubicVelocity); }
BENCHMARK(BM_FrameDefaults)->Arg(64)->Arg(128)->Arg(256)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FrameCubicVelocity)->Arg(64)->Arg(128)->Arg(256)->Unit(benchmark::kMillisecond)->UseRealTime();

/// Times `stage` alone, each iteration from the state the previous stages of a step leave.
template <typename Stage>
void stageBenchmark(benchmark::State& state, bool fire, int before, Stage stage,
                    const Config& config = kBfecc) {
  SmokeSolver& solver = warmSolver(int(state.range(0)), fire, config);
  const float dt = solver.params().frameDt;
  using Member = void (SmokeSolver::*)(float);
  const Member order[] = {&SmokeSolver::applySources, &SmokeSolver::addForces,
                          &SmokeSolver::advect, &SmokeSolver::burn, &SmokeSolver::project};
  const Snapshot start(solver);
  for (int s = 0; s < before; ++s) (solver.*order[s])(dt);
  const Snapshot input(solver);
  for (auto _ : state) {
    state.PauseTiming();
    input.restore(solver);
    state.ResumeTiming();
    stage(solver, dt);
  }
  start.restore(solver);
  state.counters["cells_per_s"] = benchmark::Counter(
      double(state.iterations()) * double(solver.density().count()), benchmark::Counter::kIsRate);
  state.counters["peak_rss_MB"] = peakRssMb();
  state.counters["rss_MB"] = rssMb();
}

void BM_Stage_applySources(benchmark::State& state) {
  stageBenchmark(state, false, 0, [](SmokeSolver& s, float dt) { s.applySources(dt); });
}
void BM_Stage_addForces(benchmark::State& state) {
  stageBenchmark(state, false, 1, [](SmokeSolver& s, float dt) { s.addForces(dt); });
}
void BM_Stage_advect(benchmark::State& state) {
  stageBenchmark(state, false, 2, [](SmokeSolver& s, float dt) { s.advect(dt); });
}
void BM_Stage_advectMacCormack(benchmark::State& state) {
  stageBenchmark(
      state, false, 2, [](SmokeSolver& s, float dt) { s.advect(dt); }, kMacCormack);
}
void BM_Stage_advectComparable(benchmark::State& state) {
  stageBenchmark(
      state, false, 2, [](SmokeSolver& s, float dt) { s.advect(dt); }, kComparable);
}
void BM_Stage_burn(benchmark::State& state) {
  stageBenchmark(state, /*fire=*/true, 3, [](SmokeSolver& s, float dt) { s.burn(dt); });
}
void projectBenchmark(benchmark::State& state, const Config& config) {
  double iterations = 0.0;
  stageBenchmark(
      state, false, 4,
      [&](SmokeSolver& s, float dt) {
        // project() adds its iterations to those of the current step: count this call's only.
        const int before = s.lastStats().pressureIterations;
        s.project(dt);
        iterations += s.lastStats().pressureIterations - before;
      },
      config);
  state.counters["pressure_iters"] = iterations / double(state.iterations());
}
void BM_Stage_project(benchmark::State& state) { projectBenchmark(state, kBfecc); }
/// Projection to Mantaflow's tolerance 1e-3.
void BM_Stage_projectComparable(benchmark::State& state) { projectBenchmark(state, kComparable); }
BENCHMARK(BM_Stage_applySources)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Stage_addForces)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Stage_advect)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Stage_advectMacCormack)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Stage_advectComparable)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Stage_burn)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Stage_project)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Stage_projectComparable)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_WriteVdb(benchmark::State& state) {
  SmokeSolver& solver = warmSolver(int(state.range(0)), /*fire=*/false);
  const std::string path =
      (std::filesystem::temp_directory_path() /
       ("plume_bench_frame_" + std::to_string(::getpid()) + ".vdb"))
          .string();
  for (auto _ : state) writeVdbFrame(path, solver);
  std::error_code ec;
  state.counters["file_MB"] = double(std::filesystem::file_size(path, ec)) / (1024.0 * 1024.0);
  std::filesystem::remove(path, ec);
  state.counters["peak_rss_MB"] = peakRssMb();
}
BENCHMARK(BM_WriteVdb)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace plume

BENCHMARK_MAIN();
