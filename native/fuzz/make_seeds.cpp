/// \file make_seeds.cpp
/// plume_fuzz_seeds OUTDIR: writes the seed corpus of every fuzz target with Plume's own writers
/// (so every checksum is valid and the fuzzer starts from files the readers accept):
/// OUTDIR/<target>/seed_<n>.bin, a few small files per format, the empty cases included.

#include "fuzz_fixtures.h"
#include "fuzz/vdb_seeds.h"
#include "solver/state_file.h"
#include "toon/toon_file.h"
#include "tracers/streak_file.h"
#include "tracers/tracer_state_file.h"

#include <cstdio>
#include <filesystem>
#include <exception>
#include <string>

using namespace plume;
namespace fs = std::filesystem;

namespace {

std::string seed(const fs::path& out, const std::string& target, int n) {
  const fs::path dir = out / target;
  fs::create_directories(dir);
  return (dir / ("seed_" + std::to_string(n) + ".bin")).string();
}

/// A small uniform drift for the tracer seeds.
void stepTracer(StreakTracer& t, int steps) {
  MacGrid3 mac;
  mac.resize(fuzz::tracerGrid().resolution);
  mac.u().fill(0.1f);
  mac.v().fill(-0.05f);
  mac.w().fill(0.9f);
  ScalarGrid density;
  density.resize(fuzz::tracerGrid().resolution);
  density.fill(0.5f);
  for (int s = 0; s < steps; ++s) t.step(mac, mac, density, 0.05f);
}

void stateSeeds(const fs::path& out) {
  SmokeSolver solver(fuzz::stateParams());
  writeState(seed(out, "state", 0), solver);  // all zero
  solver.density().fill(0.25f);
  solver.temperature().fill(1.5f);
  solver.velocity().w().fill(0.3f);
  solver.setFrame(7);
  writeState(seed(out, "state", 1), solver);
}

void tracerSeeds(const fs::path& out) {
  StreakTracer empty = fuzz::makeTracer();
  writeTracerState(seed(out, "tracer_state", 0), empty, 0);
  StreakTracer t = fuzz::makeTracer();
  t.addPointSources({{0.3f, 0.4f, 0.1f}, {0.5f, 0.5f, 0.5f}}, {0, 1},
                    {{0.f, 0.f, 1.f}, {0.f, 0.f, 0.f}});
  writeTracerState(seed(out, "tracer_state", 1), t, 1);
  stepTracer(t, 5);
  writeTracerState(seed(out, "tracer_state", 2), t, 3);

  writeStreakFile(seed(out, "streak", 0), StreakFrame{});
  writeStreakFile(seed(out, "streak", 1), t.snapshot());
  StreakFrame f;
  f.counts = {2, 0, 1};
  f.positions = {{0.1f, 0.2f, 0.3f}, {0.1f, 0.2f, 0.4f}, {0.5f, 0.5f, 0.5f}};
  f.density = {0.5f, 0.25f, 1.f};
  f.groups = {0, 0, 3};
  f.outside = {0, 1, 0};
  writeStreakFile(seed(out, "streak", 2), f);
}

void toonSeeds(const fs::path& out) {
  writeToonFile(seed(out, "toon", 0), ToonParticleState{});
  ToonParticleState s;
  s.resize(3);
  for (std::size_t i = 0; i < 3; ++i) {
    const float x = float(i);
    s.ids[i] = 2 * i + 1;
    s.positions[i] = glm::vec3(0.1f * x, 0.2f, 0.3f + x);
    s.velocities[i] = glm::vec3(0.f, 0.f, 0.5f * x);
    s.density[i] = 0.5f + x;
    s.temperature[i] = 1.f;
    s.size[i] = 0.02f * (x + 1.f);
    s.targetSize[i] = 0.03f;
    s.color[i] = 0.25f * x;
    s.age[i] = int(i);
  }
  s.nextId = 9;
  s.frame = 4;
  writeToonFile(seed(out, "toon", 1), s);
}

void pathlineSeeds(const fs::path& out) {
  int n = 0;
  for (bool half : {false, true})
    for (int nodes : {1, 2}) {
      const PathlineFileInfo info = fuzz::pathlineInfo(half);
      PathlineFileWriter w(seed(out, "pathline", n++), info);
      for (int k = 0; k < nodes; ++k) {
        PathlineGroup g;
        g.step = k;
        g.layout = info.layout;
        g.start.assign(std::size_t(info.layout.particles), glm::vec3(0.1f, 0.f, 0.05f * float(k)));
        g.velocity.resize(info.layout.values());
        g.density.resize(info.layout.values());
        g.temperature.resize(info.layout.values());
        for (std::size_t i = 0; i < info.layout.values(); ++i) {
          g.velocity[i] = glm::vec3(0.01f * float(i), 0.f, 1.f);
          g.density[i] = 0.1f * float(i % 5);
          g.temperature[i] = 1.f + float(k);
        }
        w.append(g);
      }
      w.finish();
    }
}

/// VDB frames (OpenVDB's own writer, vdb_seeds.h): a Plume volume frame and Mantaflow frames in
/// full and half precision for both VDB targets (either reader meets both kinds).
void vdbSeeds(const fs::path& out) {
  for (const char* target : {"vdb_frame", "mantaflow"}) {
    seeds::writePlumeFrameSeed(seed(out, target, 0));
    seeds::writeMantaflowSeed(seed(out, target, 1), /*half=*/false);
    seeds::writeMantaflowSeed(seed(out, target, 2), /*half=*/true);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: plume_fuzz_seeds OUTDIR\n");
    return 2;
  }
  try {
    const fs::path out(argv[1]);
    stateSeeds(out);
    tracerSeeds(out);
    toonSeeds(out);
    pathlineSeeds(out);
    vdbSeeds(out);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "plume_fuzz_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
