/// \file toon_test.cpp
/// Toon particles ([Cartoon Smoke] §2.1-2.3): bounded size changes, shrink before death, birth
/// in empty dense cells, the particle budget, determinism, parameter checks and the toon file.

#include "toon/toon_file.h"
#include "tests/toon_plume.h"
#include "toon/toon_particles.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <stdexcept>
#include "tests/temp_path.h"

namespace fs = std::filesystem;

namespace plume {
namespace {

using testing::plumeFields;
using testing::plumeGrid;
using testing::plumeParams;
using testing::plumeSources;

constexpr float kDt = 1.f / 24.f;

/// Cells holding at least one particle inside the domain.
std::set<std::size_t> occupiedCells(const ToonParticles& t) {
  const GridFrame& g = t.grid();
  std::set<std::size_t> cells;
  for (const glm::vec3& x : t.state().positions) {
    const glm::ivec3 c(glm::floor((x - g.origin) / g.cellSize));
    if (glm::all(glm::greaterThanEqual(c, glm::ivec3(0))) && glm::all(glm::lessThan(c, g.resolution)))
      cells.insert(std::size_t(c.x) + std::size_t(g.resolution.x) * (std::size_t(c.y) + std::size_t(g.resolution.y) * std::size_t(c.z)));
  }
  return cells;
}

std::map<std::uint64_t, float> sizesById(const ToonParticleState& s) {
  std::map<std::uint64_t, float> m;
  for (std::size_t n = 0; n < s.count(); ++n) m[s.ids[n]] = s.size[n];
  return m;
}

/// Checks §2.3's coherence rules between two consecutive frames: no size changes by more than
/// the step (1e-6 relative: the size moves by step in float arithmetic, one rounding), and a
/// particle that disappears had at most one step left (it shrank to 0; removal changes nothing).
void expectCoherent(const ToonParticleState& before, const ToonParticleState& after, float step) {
  const auto a = sizesById(before), b = sizesById(after);
  const float tol = step * (1.f + 1e-6f);
  for (const auto& [id, size] : a) {
    const auto it = b.find(id);
    if (it == b.end()) {
      EXPECT_LE(size, tol) << "particle " << id << " popped at size " << size;
    } else {
      EXPECT_LE(std::abs(it->second - size), tol) << "particle " << id;
    }
  }
  for (const auto& [id, size] : b)
    if (!a.count(id)) EXPECT_EQ(size, 0.f) << "newborn " << id << " must start at size 0";
}

TEST(ToonParticles, SizeNeverChangesMoreThanTheStepPerFrame) {
  const GridFrame g = plumeGrid(12, 0.1f);
  const ToonFields strong = plumeFields(g, 1.f), weak = plumeFields(g, 0.3f, -0.5f);
  ToonParticles t(plumeParams(), g);
  const float step = t.params().maxSizeStep();
  // Fields swap every 7 frames: sizes are pulled up and down across the whole ramp.
  for (int f = 0; f < 60; ++f) {
    const bool odd = (f / 7) % 2 == 1;
    const ToonParticleState before = t.state();
    t.advanceFrame(odd ? weak : strong, odd ? strong : weak, kDt, plumeSources(g));
    expectCoherent(before, t.state(), step);
  }
}

TEST(ToonParticles, ParticlesShrinkToZeroBeforeTheyAreRemoved) {
  const GridFrame g{glm::ivec3(4), 0.25f, glm::vec3(-0.5f), kDt};
  ToonFields dense;
  dense.density.resize(g.resolution, 1.f);
  dense.velocity.resize(g.resolution);
  ToonFields empty = dense;
  empty.density.fill(0.f);
  ToonParams p = plumeParams();
  ToonParticles t(p, g);
  for (int f = 0; f < 12; ++f) t.advanceFrame(dense, dense, kDt, {});
  ASSERT_EQ(t.count(), 64u);  // one birth per cell, grown to full size in 1 / 0.1 frames
  for (float s : t.state().size) EXPECT_FLOAT_EQ(s, p.sizeHigh);
  // The density drops: every particle shrinks by one step per frame and goes only at size 0.
  const float step = p.maxSizeStep();
  const int frames = int(std::ceil(p.sizeHigh / step));
  for (int f = 0; f < frames; ++f) {
    const ToonParticleState before = t.state();
    t.advanceFrame(dense, empty, kDt, {});
    expectCoherent(before, t.state(), step);
    if (f + 1 < frames) {
      ASSERT_EQ(t.count(), 64u) << "frame " << f;
      for (float s : t.state().size) EXPECT_NEAR(s, p.sizeHigh - float(f + 1) * step, 1e-6f);
    }
  }
  EXPECT_EQ(t.count(), 0u);
}

TEST(ToonParticles, BirthFillsEveryEmptyDenseCellWithinOneFrame) {
  const GridFrame g = plumeGrid(12, 0.1f);
  const ToonFields f = plumeFields(g);
  ToonParticles t(plumeParams(), g);
  std::size_t dense = 0;
  for (float d : f.density.values()) dense += d > t.params().birthDensity;
  ASSERT_GT(dense, 20u);
  for (int frame = 0; frame < 30; ++frame) {
    t.advanceFrame(f, f, kDt, plumeSources(g));
    const std::set<std::size_t> occupied = occupiedCells(t);
    for (std::size_t m = 0; m < f.density.count(); ++m)
      if (f.density[m] > t.params().birthDensity)
        ASSERT_TRUE(occupied.count(m)) << "dense cell " << m << " empty after frame " << frame;
  }
}

TEST(ToonParticles, CountStaysBoundedOverThreeHundredFrames) {
  const GridFrame g = plumeGrid(12, 0.1f);
  const ToonFields f = plumeFields(g);
  ToonParams p = plumeParams();
  p.maxCount = 150;  // fewer than the dense cells plus the emission: the budget binds
  p.emissionCount = 40;
  ToonParticles t(p, g);
  std::size_t most = 0;
  for (int frame = 0; frame < 300; ++frame) {
    t.advanceFrame(f, f, kDt, plumeSources(g));
    ASSERT_LE(t.count(), std::size_t(p.maxCount)) << "frame " << frame;
    most = std::max(most, t.count());
  }
  EXPECT_EQ(most, std::size_t(p.maxCount));
  // Particles leave through the top and new ones keep coming: ids were renewed.
  EXPECT_GT(t.state().nextId, std::uint64_t(3 * p.maxCount));
}

TEST(ToonParticles, EmissionSpreadsOverTheSourceCells) {
  const GridFrame g = plumeGrid(12, 0.1f);
  ToonFields still = plumeFields(g, 0.f, 0.f);  // no smoke: nothing is born, only emitted
  still.velocity.fill(0.f);
  ToonParams p = plumeParams();
  p.emissionCount = 3;
  ToonParticles t(p, g);
  t.advanceFrame(still, still, kDt, plumeSources(g));
  // Emitted particles start at size 0 in empty air and are removed in the next frame.
  EXPECT_EQ(t.count(), 3u);
  for (float s : t.state().size) EXPECT_EQ(s, 0.f);
  t.advanceFrame(still, still, kDt, plumeSources(g));
  EXPECT_EQ(t.count(), 3u);
  EXPECT_EQ(t.state().ids.front(), 3u);  // the first three went at size 0, three new ones came
  // Two sources of 25 cells each (at x < 0.5 m and x > 0.7 m) and 4 particles per frame: each
  // frame's particles spread over both (in turn, the first 4 frames came from the first source).
  ToonSources two;
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 5; ++i) {
      two.cells.emplace_back(i, j, 0);
      two.cells.emplace_back(7 + i, 7 + j, 0);
    }
  std::sort(two.cells.begin(), two.cells.end(), [](glm::ivec3 a, glm::ivec3 b) { return a.x < b.x; });
  p.emissionCount = 4;
  ToonParticles burst(p, g);
  for (int f = 0; f < 3; ++f) {
    burst.advanceFrame(still, still, kDt, two);
    int left = 0;
    for (const glm::vec3& x : burst.state().positions) left += x.x < 0.6f;
    EXPECT_EQ(left, 2) << "frame " << f;
    EXPECT_EQ(burst.count(), 4u);
  }
}

ToonParticleState runPlume(int threads, ToonIntegration integration) {
  const GridFrame g = plumeGrid(10, 0.1f);
  const ToonFields a = plumeFields(g, 1.f), b = plumeFields(g, 0.8f, 0.6f);
  ToonParams p = plumeParams();
  p.threads = threads;
  p.integration = integration;
  p.maxCount = 400;
  ToonParticles t(p, g);
  for (int f = 0; f < 40; ++f) t.advanceFrame(f % 2 ? b : a, f % 2 ? a : b, 2.f * kDt, plumeSources(g));
  return t.state();
}

template <typename T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

/// Every array and counter of a and b, bit for bit.
void expectSameParticles(const ToonParticleState& a, const ToonParticleState& b) {
  EXPECT_EQ(a.frame, b.frame);
  EXPECT_EQ(a.nextId, b.nextId);
  EXPECT_TRUE(sameBits(a.ids, b.ids));
  EXPECT_TRUE(sameBits(a.positions, b.positions));
  EXPECT_TRUE(sameBits(a.velocities, b.velocities));
  for (const auto member : {&ToonParticleState::density, &ToonParticleState::temperature,
                            &ToonParticleState::size, &ToonParticleState::targetSize,
                            &ToonParticleState::color})
    EXPECT_TRUE(sameBits(a.*member, b.*member));
  EXPECT_TRUE(sameBits(a.age, b.age));
}

TEST(ToonParticles, BitIdenticalAtOneAndTwoThreads) {
  for (ToonIntegration integration : {ToonIntegration::Euler, ToonIntegration::Midpoint}) {
    const ToonParticleState one = runPlume(1, integration), two = runPlume(2, integration);
    ASSERT_GT(one.count(), 100u);
    expectSameParticles(one, two);
  }
}

TEST(ToonParticles, EulerMovesAParticleByVelocityTimesDt) {
  // Uniform flow: Euler is exact, whatever the substeps (§2.1).
  const GridFrame g{glm::ivec3(8), 0.5f, glm::vec3(0.f), kDt};
  ToonFields f;
  f.density.resize(g.resolution, 1.f);
  f.velocity.resize(g.resolution);
  f.velocity.u().fill(30.f);  // 2.5 cells per frame: three substeps at cfl 1
  f.velocity.w().fill(-6.f);
  ToonParticles t(plumeParams(), g);
  ToonParticleState s;
  s.resize(1);
  s.positions[0] = glm::vec3(0.3f, 2.f, 3.f);
  s.nextId = 1;
  t.setState(s);
  EXPECT_EQ(t.substeps(f, f, kDt), 3);
  t.advanceFrame(f, f, kDt, {});
  ASSERT_EQ(t.state().ids[0], 0u);
  const glm::vec3 x = t.state().positions[0];
  EXPECT_NEAR(x.x, 0.3f + 30.f * kDt, 1e-5f);
  EXPECT_NEAR(x.y, 2.f, 1e-6f);
  EXPECT_NEAR(x.z, 3.f - 6.f * kDt, 1e-5f);
  EXPECT_NEAR(t.state().velocities[0].x, 30.f, 1e-5f);
}

/// invalid_argument whose message names `setting`.
template <typename Fn>
void expectRejected(const Fn& fn, const std::string& setting) {
  try {
    fn();
    ADD_FAILURE() << setting << " was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(setting), std::string::npos) << e.what();
  }
}

TEST(ToonParams, BadSettingsNameTheSetting) {
  const std::vector<std::pair<std::string, void (*)(ToonParams&)>> cases = {
      {"emission_count", [](ToonParams& p) { p.emissionCount = -1; }},
      {"birth_density", [](ToonParams& p) { p.birthDensity = p.deathDensity; }},
      {"death_density", [](ToonParams& p) { p.deathDensity = -0.1f; }},
      {"ramp_density_high", [](ToonParams& p) { p.rampDensityHigh = p.rampDensityLow; }},
      {"size_low", [](ToonParams& p) { p.sizeLow = -1.f; }},
      {"size_high", [](ToonParams& p) { p.sizeHigh = std::nanf(""); }},
      {"max_size_change", [](ToonParams& p) { p.maxSizeChange = 0.f; }},
      {"max_size_change", [](ToonParams& p) { p.maxSizeChange = 1.5f; }},
      {"max_count", [](ToonParams& p) { p.maxCount = 0; }},
      {"cfl", [](ToonParams& p) { p.cfl = 50.f; }},
      {"stretch_factor", [](ToonParams& p) { p.stretchFactor = -1.f; }},
      {"color_high", [](ToonParams& p) { p.colorHigh = p.colorLow; }},
      {"threads", [](ToonParams& p) { p.threads = -2; }},
  };
  for (const auto& [name, spoil] : cases) {
    ToonParams p;
    spoil(p);
    expectRejected([&] { p.validate(); }, name);
    expectRejected([&] { ToonParticles(p, plumeGrid(4, 0.1f)); }, name);
  }
  ToonParams ok;
  EXPECT_NO_THROW(ok.validate());
  expectRejected([&] { ToonParticles(ok, GridFrame{glm::ivec3(0, 4, 4), 0.1f, glm::vec3(0.f), kDt}); },
                 "resolution");
}

TEST(ToonParticles, BadFramesAndSourcesChangeNothing) {
  const GridFrame g = plumeGrid(6, 0.1f);
  const ToonFields f = plumeFields(g);
  ToonParticles t(plumeParams(), g);
  t.advanceFrame(f, f, kDt, plumeSources(g));
  const ToonParticleState before = t.state();
  expectRejected([&] { t.advanceFrame(f, f, 0.f, {}); }, "dt");
  expectRejected([&] { t.advanceFrame(f, plumeFields(plumeGrid(5, 0.1f)), kDt, {}); }, "grid");
  ToonSources bad;
  bad.cells.emplace_back(6, 0, 0);
  expectRejected([&] { t.advanceFrame(f, f, kDt, bad); }, "source cell");
  ToonFields fast = f;
  fast.velocity.w().fill(1e9f);
  EXPECT_THROW(t.advanceFrame(f, fast, kDt, {}), std::runtime_error);
  EXPECT_TRUE(sameBits(before.positions, t.state().positions));
  EXPECT_EQ(before.frame, t.state().frame);
}

TEST(ToonParams, RampsAreLinearAndClamped) {
  ToonParams p = plumeParams();
  EXPECT_FLOAT_EQ(p.rampSize(-1.f), p.sizeLow);
  EXPECT_FLOAT_EQ(p.rampSize(0.55f), 0.5f * (p.sizeLow + p.sizeHigh));
  EXPECT_FLOAT_EQ(p.rampSize(9.f), p.sizeHigh);
  p.colorDriver = ToonColorDriver::Speed;
  p.colorLow = 1.f;
  p.colorHigh = 3.f;
  EXPECT_FLOAT_EQ(p.colorParameter(0.f, 0.f, 2.5f), 0.75f);
  p.colorDriver = ToonColorDriver::Temperature;
  EXPECT_FLOAT_EQ(p.colorParameter(0.f, 5.f, 0.f), 1.f);
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(plume::test::tempPath("toon_test_" + name));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

ToonParticleState somePlume() {
  const GridFrame g = plumeGrid(8, 0.1f);
  const ToonFields f = plumeFields(g);
  ToonParticles t(plumeParams(), g);
  for (int n = 0; n < 5; ++n) t.advanceFrame(f, f, kDt, plumeSources(g));
  return t.state();
}

TEST(ToonFile, RoundTripIsExactAndResumes) {
  const fs::path dir = scratch("round_trip");
  const std::string path = (dir / toonFileName(5)).string();
  EXPECT_EQ(toonFileName(5), "toon_0005.bin");
  const ToonParticleState s = somePlume();
  writeToonFile(path, s);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  const ToonParticleState r = readToonFile(path);
  expectSameParticles(r, s);
  // Resuming from the file continues exactly as the uninterrupted run.
  const GridFrame g = plumeGrid(8, 0.1f);
  const ToonFields f = plumeFields(g);
  ToonParticles a(plumeParams(), g), b(plumeParams(), g);
  a.setState(s);
  b.setState(r);
  a.advanceFrame(f, f, kDt, plumeSources(g));
  b.advanceFrame(f, f, kDt, plumeSources(g));
  EXPECT_TRUE(sameBits(a.state().positions, b.state().positions));
}

TEST(ToonFile, CorruptOrTruncatedFilesThrow) {
  const fs::path dir = scratch("corrupt");
  const std::string path = (dir / "toon_0001.bin").string();
  writeToonFile(path, somePlume());
  std::vector<char> bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  ASSERT_GT(bytes.size(), 200u);
  auto writeBytes = [&](const std::vector<char>& b) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(b.data(), std::streamsize(b.size()));
  };
  auto expectBad = [&](const std::vector<char>& b, const char* what) {
    writeBytes(b);
    EXPECT_THROW(readToonFile(path), std::runtime_error) << what;
  };
  expectBad(std::vector<char>(bytes.begin(), bytes.end() - 1), "one byte short");
  expectBad(std::vector<char>(bytes.begin(), bytes.begin() + 20), "header only");
  std::vector<char> flipped = bytes;
  flipped[bytes.size() / 2] ^= 0x10;
  expectBad(flipped, "a flipped bit");
  std::vector<char> count = bytes;
  count[9 + 4 + 8 + 8 + 7] = 0x7f;  // the top byte of the particle count
  expectBad(count, "a huge count");
  std::vector<char> magic = bytes;
  magic[0] = 'X';
  expectBad(magic, "bad magic");
  EXPECT_THROW(readToonFile((dir / "missing.bin").string()), std::runtime_error);
}

TEST(ToonFile, InconsistentStatesAreNotWritten) {
  ToonParticleState s = somePlume();
  s.size.pop_back();
  EXPECT_THROW(writeToonFile((scratch("bad_state") / "t.bin").string(), s), std::invalid_argument);
}

}  // namespace
}  // namespace plume
