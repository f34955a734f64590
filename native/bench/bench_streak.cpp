// Benchmarks of the streak-surface pipeline ([Smoke Surfaces] §3.3–3.4).
//  * Figure 1's scale: 20 point sources × 300 frames; what "Build Surfaces" does in the native core (h,
//    clusters, order, then per frame the NURBS and density map of every surface).
//  * An artist's scale: clustering that scales. 20,000 streaklines × 60 frames (N(t) = t + 1, so 60
//    particles at the end): 1,250 clumps of 16 point sources spread over a sphere, rising,
//    spreading and stirred by a smooth unsteady flow. Sparse distances, clusters and greedy
//    orders in <= 2 s and <= 1 GB peak, the same surfaces as the brute force (checked on 2,000
//    streaklines, where the brute force is timed for the ratio), at a threshold that makes the
//    clumps surfaces and at the default h0 (the mean of h), which joins nearly everything.
//    Figures are printed, never asserted (shared machines).
// Run: build/native/plume_bench_streak
#include "core/parallel.h"
#include "core/rng.h"
#include "nurbs/density_map.h"
#include "nurbs/interpolation.h"
#include "streak/brute_force.h"
#include "streak/clustering.h"
#include "streak/streak_moments.h"
#include "tracers/streak_frame.h"

#include <benchmark/benchmark.h>

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

namespace plume {
namespace {

// --- a small incense plume over a long shot -----------------------------------------------

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

// --- thousands of streaklines ----------------------------------------------------------------

constexpr int kClump = 16;       // point sources per clump (10–20 per source cell, §3.2)
constexpr int kShotFrames = 60;  // N(t) = t + 1
constexpr int kModes = 8;        // stirring modes

/// CPU seconds of the process so far, all threads (user + system): a figure that the load of a
/// shared machine changes far less than the wall time.
double processCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

/// kB from /proc/self/status ("VmRSS", "VmHWM").
double statusKb(const std::string& key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key + ":", 0) == 0) return std::stod(line.substr(key.size() + 1));
  return 0.0;
}

std::vector<int> firstIds(int n) {
  std::vector<int> ids(static_cast<std::size_t>(n));
  for (int s = 0; s < n; ++s) ids[std::size_t(s)] = s;
  return ids;
}

/// Seeded stirring: wave vectors κ_k (~30 cm waves), directions d_k, rates ω_k, phases φ_k.
struct Stirring {
  glm::vec3 kappa[kModes], dir[kModes];
  double omega[kModes], phi[kModes];
  Stirring() {
    Rng rng(/*seed=*/14, /*stream=*/0);
    for (int k = 0; k < kModes; ++k) {
      kappa[k] = 20.f * glm::normalize(glm::vec3(rng.normal(), rng.normal(), rng.normal()));
      dir[k] = glm::normalize(glm::vec3(rng.normal(), rng.normal(), rng.normal()));
      omega[k] = rng.uniform(0.1, 0.4);
      phi[k] = rng.uniform(0.0, 6.283185307179586);
    }
  }
};

/// A plume from clumps of point sources on a sphere (radius 0.25 m, centre 0.35 m up): clump
/// centres on a Fibonacci sphere (about 2.5 cm apart), sources within 3 mm of their centre per
/// axis, consecutive IDs per clump (as random_points_in_cells gives them per cell). Particle i
/// of source s on frame t was emitted at e = i and is a = t − e frames old:
///   p = s + 2.5 cm·a up + 4 mm·a along the sphere's normal (spreading)
///       + 4 mm·a · Σ_k d_k sin(κ_k·s + ω_k e + φ_k)   (stirring: smooth in s, unsteady in e).
/// Neighbouring streaklines drift apart with age, and puffs of different emission times follow
/// different paths, as in a baked plume.
std::vector<StreakFrame> sphereShot(int sources) {
  const int clumps = (sources + kClump - 1) / kClump;
  const Stirring w;
  const glm::vec3 centre(0.f, 0.f, 0.35f);
  const std::size_t n = static_cast<std::size_t>(sources);
  std::vector<glm::vec3> start(n), normal(n);
  for (int s = 0; s < sources; ++s) {
    const int c = s / kClump;
    const double z = 1.0 - 2.0 * (c + 0.5) / clumps, r = std::sqrt(1.0 - z * z);
    const double angle = 2.399963229728653 * c;  // golden angle
    const glm::vec3 u(float(r * std::cos(angle)), float(r * std::sin(angle)), float(z));
    Rng jitter(14, std::uint64_t(s) + 1);
    const glm::vec3 offset(jitter.uniform(-1, 1), jitter.uniform(-1, 1), jitter.uniform(-1, 1));
    start[std::size_t(s)] = centre + 0.25f * u + 0.003f * offset;
    normal[std::size_t(s)] = u;
  }
  // sin(κ·s + ω e + φ) = sin(κ·s) cos(ω e + φ) + cos(κ·s) sin(ω e + φ): per source, per emission.
  std::vector<double> sinS(n * kModes), cosS(n * kModes);
  for (std::size_t s = 0; s < n; ++s)
    for (int k = 0; k < kModes; ++k) {
      const double x = glm::dot(w.kappa[k], start[s]);
      sinS[s * kModes + std::size_t(k)] = std::sin(x);
      cosS[s * kModes + std::size_t(k)] = std::cos(x);
    }
  std::vector<double> cosE(std::size_t(kShotFrames) * kModes), sinE(cosE.size());
  for (int e = 0; e < kShotFrames; ++e)
    for (int k = 0; k < kModes; ++k) {
      cosE[std::size_t(e) * kModes + std::size_t(k)] = std::cos(w.omega[k] * e + w.phi[k]);
      sinE[std::size_t(e) * kModes + std::size_t(k)] = std::sin(w.omega[k] * e + w.phi[k]);
    }
  std::vector<StreakFrame> frames(kShotFrames);
  for (int t = 0; t < kShotFrames; ++t) {
    StreakFrame& f = frames[std::size_t(t)];
    f.counts.assign(n, t + 1);
    f.groups.assign(n, 0);
    f.positions.resize(n * std::size_t(t + 1));
    f.density.assign(f.positions.size(), 1.f);
    f.outside.assign(f.positions.size(), 0);
  }
  parallelFor(0, sources, [&](int s) {
    const double* ss = sinS.data() + std::size_t(s) * kModes;
    const double* cs = cosS.data() + std::size_t(s) * kModes;
    for (int t = 0; t < kShotFrames; ++t) {
      const std::size_t N = std::size_t(t) + 1;
      glm::vec3* out = frames[std::size_t(t)].positions.data() + std::size_t(s) * N;
      for (std::size_t i = 0; i < N; ++i) {
        const int e = int(i);
        const float a = float(t - e);
        const double* ce = cosE.data() + std::size_t(e) * kModes;
        const double* se = sinE.data() + std::size_t(e) * kModes;
        glm::dvec3 stir(0.0);
        for (int k = 0; k < kModes; ++k) stir += glm::dvec3(w.dir[k]) * (ss[k] * ce[k] + cs[k] * se[k]);
        out[i] = start[std::size_t(s)] + glm::vec3(0.f, 0.f, 0.025f * a) +
                 0.004f * a * normal[std::size_t(s)] + 0.004f * a * glm::vec3(stir);
      }
    }
  });
  return frames;
}

/// The threshold the benchmark clusters with: 3× the median h between two sources of one clump
/// (first 40 clumps), so that the surfaces are the clumps, as an artist tunes h0 (Figure 4).
/// The default h0, the mean of h, joins nearly everything on such a sphere.
double clumpThreshold(const std::vector<StreakFrame>& frames) {
  const int n = std::min(frames.back().sourceCount(), 40 * kClump);
  const StreakGroup g(SharedStreakFrames(SharedStreakFrames(), &frames), firstIds(n));
  std::vector<double> within;
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n && b / kClump == a / kClump; ++b) within.push_back(streakDistance(g, a, b));
  std::nth_element(within.begin(), within.begin() + std::ptrdiff_t(within.size() / 2), within.end());
  return 3.0 * within[within.size() / 2];
}

/// The shot of n streaklines, made once per process.
const std::vector<StreakFrame>& shot(int sources) {
  static std::map<int, std::vector<StreakFrame>> shots;
  auto it = shots.find(sources);
  if (it == shots.end()) it = shots.emplace(sources, sphereShot(sources)).first;
  return it->second;
}

/// The threshold of a run: range(1) = 0 the clump threshold, 1 the default h0 (-1, the mean).
double benchThreshold(const benchmark::State& state, const std::vector<StreakFrame>& frames) {
  return state.range(1) == 0 ? clumpThreshold(frames) : -1.0;
}

void clusterCounters(benchmark::State& state, const std::vector<StreakSurface>& surfaces, int n) {
  std::size_t largest = 0, used = 0;
  for (const StreakSurface& s : surfaces) {
    largest = std::max(largest, s.sources.size());
    used += s.sources.size();
  }
  state.counters["n"] = n;
  state.counters["surfaces"] = double(surfaces.size());
  state.counters["mean_size"] = surfaces.empty() ? 0.0 : double(used) / double(surfaces.size());
  state.counters["largest"] = double(largest);
}

/// Sparse clustering, end to end (buildSurfaces: default-h0 moments, pruning directions,
/// pairs, clusters, greedy orders).
void BM_StreakClusterSparse(benchmark::State& state) {
  const int n = int(state.range(0));
  const double rssBefore = statusKb("VmRSS");
  const std::vector<StreakFrame>& frames = shot(n);
  const double framesMb = (statusKb("VmRSS") - rssBefore) / 1024.0;
  const double h0 = benchThreshold(state, frames);
  std::vector<StreakSurface> surfaces;
  const double cpu0 = processCpuSeconds();
  for (auto _ : state) {
    surfaces = buildSurfaces(frames, {}, h0);
    benchmark::DoNotOptimize(surfaces.data());
  }
  const double cpuPerRun = (processCpuSeconds() - cpu0) / double(state.iterations());
  clusterCounters(state, surfaces, n);
  state.counters["cpu_s_all_threads"] = cpuPerRun;
  // The work of the pair search, outside the timing.
  DistanceParams params;
  params.reach = h0;  // < 0: the mean
  const StreakDistances d(StreakGroup(SharedStreakFrames(SharedStreakFrames(), &frames), firstIds(n)),
                          params);
  const double allPairs = 0.5 * double(n) * double(n - 1), peakMb = statusKb("VmHWM") / 1024.0;
  state.counters["h0_over_mean"] = d.reach() / d.meanDistance();
  state.counters["examined_of_all_pairs"] = double(d.stats().examined) / allPairs;
  state.counters["exact_of_all_pairs"] = double(d.stats().exact) / allPairs;
  state.counters["kept_pairs"] = double(d.stats().kept);
  state.counters["frames_MB"] = framesMb;
  state.counters["peak_RSS_MB"] = peakMb;
  std::printf("  n = %d: h0 = %.4g (%.3g × mean %.4g); %zu surfaces, largest %.0f; pairs examined "
              "%.0f, exact h %.0f, kept %.0f of n²/2 = %.0f; %.2f s CPU (all threads) a run; "
              "frames %.0f MB, peak RSS %.0f MB\n",
              n, d.reach(), d.reach() / d.meanDistance(), d.meanDistance(), surfaces.size(),
              state.counters["largest"].value, double(d.stats().examined), double(d.stats().exact),
              double(d.stats().kept), allPairs, cpuPerRun, framesMb, peakMb);
}

/// The brute force over all pairs (dense matrix) on the same layout, and whether it agrees.
void BM_StreakClusterBruteForce(benchmark::State& state) {
  const int n = int(state.range(0));
  const std::vector<StreakFrame>& frames = shot(n);
  const double h0 = benchThreshold(state, frames);
  std::vector<StreakSurface> surfaces;
  const double cpu0 = processCpuSeconds();
  for (auto _ : state) {
    surfaces = bruteForceSurfaces(frames, {}, h0);
    benchmark::DoNotOptimize(surfaces.data());
  }
  clusterCounters(state, surfaces, n);
  state.counters["cpu_s_all_threads"] = (processCpuSeconds() - cpu0) / double(state.iterations());
  const std::vector<StreakSurface> sparse = buildSurfaces(frames, {}, h0);
  bool same = sparse.size() == surfaces.size();
  for (std::size_t k = 0; same && k < sparse.size(); ++k) same = sparse[k].sources == surfaces[k].sources;
  state.counters["same_as_sparse"] = same ? 1.0 : 0.0;
  std::printf("  n = %d: brute force and sparse give %s surfaces\n", n, same ? "the same" : "DIFFERENT");
}

/// The default h0 (mean of h) without the pairs: centred sums over n · particles · frames.
void BM_StreakDefaultThreshold(benchmark::State& state) {
  const int n = int(state.range(0));
  const StreakGroup g(SharedStreakFrames(SharedStreakFrames(), &shot(n)), firstIds(n));
  double mean = 0.0;
  for (auto _ : state) {
    mean = streakMoments(g).meanDistance;
    benchmark::DoNotOptimize(mean);
  }
  state.counters["mean_h"] = mean;
}

BENCHMARK(BM_StreakClustering)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_StreakPipeline)->Unit(benchmark::kMillisecond)->UseRealTime();
// The big shot first, so that its peak RSS is its own. Args: streaklines, threshold (0: clumps,
// 1: the default h0, which on a sphere of sources joins nearly all of them into one surface).
BENCHMARK(BM_StreakClusterSparse)
    ->Args({20000, 0})->Args({2000, 0})->Args({2000, 1})
    ->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_StreakDefaultThreshold)
    ->Arg(20000)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_StreakClusterBruteForce)
    ->Args({2000, 0})->Args({2000, 1})
    ->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

}  // namespace
}  // namespace plume

BENCHMARK_MAIN();
