/// \file tracer_state_test.cpp
/// Tracer checkpoints ([Smoke Surfaces] §3.2; tracers/tracer_state_file.h): a tracer restored from
/// a checkpoint continues bit for bit like the one that was saved, and truncated, corrupt or
/// mismatched files are refused by name, leaving the tracer untouched.

#include "io/byte_buffer.h"
#include "tracers/tracer_state_file.h"
#include "tracers/streak_tracer.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include "tests/temp_path.h"

namespace fs = std::filesystem;

namespace plume {
namespace {

/// 8³ cells of size 1/8 at the origin; open on every side but the floor.
GridFrame grid() { return GridFrame{glm::ivec3(8), 0.125f, glm::vec3(0.f), 1.f / 24.f}; }
std::array<Boundary, 6> sides() {
  return {Boundary::Open, Boundary::Open, Boundary::Open, Boundary::Open, Boundary::Closed,
          Boundary::Open};
}

StreakTracer makeTracer(int emissionPeriod = 2) {
  StreakParams p;
  p.emissionPeriod = emissionPeriod;
  return StreakTracer(p, grid(), sides());
}

/// A uniform upward drift that grows with `t` (time-varying, so start and end fields differ) and
/// a density ramp along z: particles rise, sample changing densities and leave through +z.
struct Fields {
  MacGrid3 before, after;
  ScalarGrid density;
};
void fieldsAt(int step, Fields& f) {
  auto fill = [](MacGrid3& mac, float t) {
    mac.resize(grid().resolution);
    mac.u().fill(0.1f * t);
    mac.v().fill(-0.05f);
    mac.w().fill(0.9f + 0.2f * t);
  };
  fill(f.before, float(step));
  fill(f.after, float(step + 1));
  f.density.resize(grid().resolution);
  const glm::ivec3 n = f.density.size();
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) f.density(i, j, k) = 0.1f * float(k + step) + 0.01f * float(i);
}

void run(StreakTracer& t, int from, int to) {
  Fields f;
  for (int s = from; s < to; ++s) {
    fieldsAt(s, f);
    t.step(f.before, f.after, f.density, 0.05f);
  }
}

void addSources(StreakTracer& t) {
  t.addPointSources({{0.3f, 0.4f, 0.1f}, {0.5f, 0.5f, 0.5f}, {0.7f, 0.2f, 0.3f}}, {0, 0, 1},
                    {{0.f, 0.f, 1.f}, {0.f, 0.f, 0.f}, {0.2f, 0.f, 0.5f}});
}

bool sameBits(const void* a, const void* b, std::size_t n) { return n == 0 || std::memcmp(a, b, n) == 0; }

void expectSameState(const StreakTracer& a, const StreakTracer& b) {
  const StreakTracerState &x = a.state(), &y = b.state();
  EXPECT_EQ(x.steps, y.steps);
  EXPECT_EQ(x.emissions, y.emissions);
  EXPECT_EQ(x.lastEmissionStep, y.lastEmissionStep);
  EXPECT_EQ(x.emitting, y.emitting);
  ASSERT_EQ(x.sources.size(), y.sources.size());
  for (std::size_t s = 0; s < x.sources.size(); ++s) {
    EXPECT_EQ(x.sources[s].position, y.sources[s].position);
    EXPECT_EQ(x.sources[s].group, y.sources[s].group);
    EXPECT_EQ(x.sources[s].velocity, y.sources[s].velocity);
  }
  ASSERT_EQ(x.positions.size(), y.positions.size());
  EXPECT_TRUE(sameBits(x.positions.data(), y.positions.data(), x.positions.size() * 12));
  EXPECT_TRUE(sameBits(x.exitVelocity.data(), y.exitVelocity.data(), x.exitVelocity.size() * 12));
  EXPECT_EQ(x.density, y.density);
  EXPECT_EQ(x.outside, y.outside);
}

void expectSameSnapshot(const StreakTracer& a, const StreakTracer& b) {
  const StreakFrame x = a.snapshot(), y = b.snapshot();
  EXPECT_EQ(x.counts, y.counts);
  EXPECT_TRUE(sameBits(x.positions.data(), y.positions.data(), x.positions.size() * 12));
  EXPECT_EQ(x.density, y.density);
  EXPECT_EQ(x.groups, y.groups);
}

fs::path scratchDir(const std::string& name) {
  const fs::path dir = fs::path(plume::test::tempPath("tracer_state_test_" + name));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<unsigned char> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void writeBytes(const std::string& path, const std::vector<unsigned char>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

/// Rewrites the trailing checksum, so a change inside the file passes the checksum test and
/// reaches the size and consistency checks.
void resign(std::vector<unsigned char>& bytes) {
  const std::uint64_t sum = fnv1a64(bytes.data(), bytes.size() - 8);
  for (int b = 0; b < 8; ++b) bytes[bytes.size() - 8 + std::size_t(b)] = (sum >> (8 * b)) & 0xff;
}

TEST(TracerStateFile, RestoredTracerContinuesBitForBit) {
  const fs::path dir = scratchDir("round_trip");
  StreakTracer straight = makeTracer(), saved = makeTracer();
  addSources(straight);
  addSources(saved);
  run(straight, 0, 25);
  run(saved, 0, 11);  // odd: the next emission is half a period away
  ASSERT_GT(saved.state().outside[0], 0) << "the oldest particles should have left through +z";
  const std::string path = (dir / "tracer_state.bin").string();
  writeTracerState(path, saved, 42);
  for (const auto& e : fs::directory_iterator(dir)) EXPECT_NE(e.path().extension(), ".tmp");

  StreakTracer restored = makeTracer();  // no sources: they come from the file
  EXPECT_EQ(readTracerState(path, restored), 42);
  expectSameState(restored, saved);
  run(restored, 11, 25);
  expectSameState(restored, straight);
  expectSameSnapshot(restored, straight);
}

TEST(TracerStateFile, PausedTracerRestoresPausedAndContinuesBitForBit) {
  // Figure 10: emission off after step 6, back on after step 16. The checkpoint is taken at step
  // 10, right after a skipped instant: the restored tracer must neither emit at instants 12, 14
  // and 16 nor treat the row of instant 6 as newborn (its source velocity would move it
  // differently).
  const fs::path dir = scratchDir("paused");
  StreakTracer straight = makeTracer(), saved = makeTracer();
  for (StreakTracer* t : {&straight, &saved}) {
    addSources(*t);
    run(*t, 0, 6);
    t->setEmitting(false);
  }
  run(straight, 6, 16);
  run(saved, 6, 10);
  EXPECT_EQ(saved.state().emissions, 4);  // instants 0, 2, 4, 6; 8 and 10 skipped
  const std::string path = (dir / "tracer_state.bin").string();
  writeTracerState(path, saved, 10);
  StreakTracer restored = makeTracer();
  EXPECT_TRUE(restored.emitting());
  EXPECT_EQ(readTracerState(path, restored), 10);
  EXPECT_FALSE(restored.emitting());
  EXPECT_EQ(restored.state().lastEmissionStep, 6);
  expectSameState(restored, saved);
  run(restored, 10, 16);
  expectSameState(restored, straight);
  EXPECT_EQ(restored.particlesPerSource(), 4);
  for (StreakTracer* t : {&straight, &restored}) {
    t->setEmitting(true);
    run(*t, 16, 25);
  }
  expectSameState(restored, straight);
  EXPECT_EQ(restored.particlesPerSource(), 4 + 4);  // instants 18, 20, 22, 24
  expectSameSnapshot(restored, straight);
}

TEST(TracerStateFile, ReadsVersionOneFilesAsNeverPaused) {
  // A version 1 file is a version 2 file without the 9 bytes of the pause fields (after the
  // particle count, at offset 88).
  const fs::path dir = scratchDir("version1");
  StreakTracer saved = makeTracer();
  addSources(saved);
  run(saved, 0, 11);
  const std::string path = (dir / "tracer_state.bin").string();
  writeTracerState(path, saved, 11);
  std::vector<unsigned char> bytes = readBytes(path);
  bytes.erase(bytes.begin() + 88, bytes.begin() + 88 + 9);
  bytes[10] = 1;
  resign(bytes);
  writeBytes(path, bytes);
  StreakTracer restored = makeTracer();
  EXPECT_EQ(readTracerState(path, restored), 11);
  expectSameState(restored, saved);  // youngest emission at step 10, emitting
}

TEST(TracerStateFile, BadFilesThrowAndLeaveTheTracerUnchanged) {
  const fs::path dir = scratchDir("bad");
  StreakTracer saved = makeTracer(), target = makeTracer(), reference = makeTracer();
  for (StreakTracer* t : {&saved, &target, &reference}) addSources(*t);
  run(saved, 0, 7);
  run(target, 0, 3);
  run(reference, 0, 3);
  const std::string good = (dir / "good.bin").string(), bad = (dir / "bad.bin").string();
  writeTracerState(good, saved, 7);
  const std::vector<unsigned char> bytes = readBytes(good);

  auto expectRejected = [&](const std::vector<unsigned char>& content, const char* what,
                            const char* says) {
    writeBytes(bad, content);
    try {
      readTracerState(bad, target);
      ADD_FAILURE() << "accepted a " << what << " file";
    } catch (const std::runtime_error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(bad), std::string::npos) << m;
      EXPECT_NE(m.find(says), std::string::npos) << what << ": " << m;
    }
    expectSameState(target, reference);
  };
  expectRejected({bytes.begin(), bytes.begin() + std::ptrdiff_t(bytes.size() / 2)}, "truncated",
                 "checksum");
  expectRejected({bytes.begin(), bytes.begin() + 30}, "header-only", "truncated");
  expectRejected({}, "empty", "truncated");
  std::vector<unsigned char> flipped = bytes;
  flipped[bytes.size() / 2] ^= 0x10;
  expectRejected(flipped, "corrupt", "checksum");
  std::vector<unsigned char> magic = bytes;
  magic[0] = 'X';
  expectRejected(magic, "bad-magic", "bad magic");
  std::vector<unsigned char> version = bytes;
  version[10] = 9;
  expectRejected(version, "newer", "version 9");
  // Consistent checksums over inconsistent contents: the counts are checked, never trusted.
  std::vector<unsigned char> huge = bytes;
  huge[72 + 7] = 0x7f;  // top byte of the source count (offset 72)
  resign(huge);
  expectRejected(huge, "huge-count", "do not fill it exactly");
  std::vector<unsigned char> emissions = bytes;
  emissions[68] += 1;  // emission count (offset 68) no longer follows from the steps
  resign(emissions);
  expectRejected(emissions, "inconsistent", "is corrupt");
  std::vector<unsigned char> flag = bytes;
  flag[bytes.size() - 8 - 12 * saved.state().positions.size() - 1] = 2;  // last outside flag
  resign(flag);
  expectRejected(flag, "bad-flag", "outside flag");
  std::vector<unsigned char> emitting = bytes;
  emitting[88 + 8] = 2;  // the emitting flag (offset 96) is 0 or 1
  resign(emitting);
  expectRejected(emitting, "bad-emitting", "emitting flag 2");
  EXPECT_THROW(readTracerState((dir / "nope.bin").string(), target), std::runtime_error);
  expectSameState(target, reference);

  // A checkpoint of other settings is refused by name.
  StreakTracer otherPeriod = makeTracer(3);
  EXPECT_THROW(
      {
        try {
          readTracerState(good, otherPeriod);
        } catch (const std::runtime_error& e) {
          EXPECT_NE(std::string(e.what()).find("emission_period 2"), std::string::npos) << e.what();
          throw;
        }
      },
      std::runtime_error);
  StreakTracer otherGrid(StreakParams{}, GridFrame{glm::ivec3(4), 0.25f, glm::vec3(0.f), 0.04f},
                         sides());
  StreakParams same;
  same.emissionPeriod = 2;
  StreakTracer otherBox(same, GridFrame{glm::ivec3(8), 0.25f, glm::vec3(0.f), 0.04f}, sides());
  StreakTracer otherSides(same, grid(), {Boundary::Closed, Boundary::Open, Boundary::Open,
                                         Boundary::Open, Boundary::Closed, Boundary::Open});
  for (StreakTracer* t : {&otherGrid, &otherBox, &otherSides})
    EXPECT_THROW(readTracerState(good, *t), std::runtime_error);
  EXPECT_EQ(otherSides.sourceCount(), 0);
}

TEST(TracerStateFile, UnwritablePathThrows) {
  const fs::path dir = scratchDir("unwritable");
  StreakTracer t = makeTracer();
  const std::string path = (dir / "missing" / "tracer_state.bin").string();
  EXPECT_THROW(writeTracerState(path, t, 1), std::runtime_error);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
}

TEST(StreakTracerState, SetStateValidatesAndKeepsTheTracerOnError) {
  StreakTracer t = makeTracer(), reference = makeTracer();
  addSources(t);
  addSources(reference);
  StreakTracerState s = t.state();
  s.steps = 4;
  s.lastEmissionStep = 4;  // a row emitted at step 4, yet only the first row is held
  EXPECT_THROW(t.setState(s), std::invalid_argument);
  s = t.state();
  s.sources[1].position = glm::vec3(2.f);  // outside the unit domain
  EXPECT_THROW(t.setState(s), std::invalid_argument);
  s = t.state();
  s.density.pop_back();
  EXPECT_THROW(t.setState(s), std::invalid_argument);
  expectSameState(t, reference);
  s = t.state();
  s.positions[0].x = 5.f;  // particles may be anywhere (outside ones keep moving)
  t.setState(s);
  EXPECT_EQ(t.state().positions[0].x, 5.f);
}

}  // namespace
}  // namespace plume
