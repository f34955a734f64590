/// \file io_test.cpp
/// Per-frame VDB files and solver checkpoints: round trips, atomic writes, corrupt files.

#include "solver/state_file.h"
#include "io/vdb_frame.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>
#include "tests/temp_path.h"

namespace fs = std::filesystem;

namespace plume {
namespace {

/// A fresh, empty directory per test.
fs::path scratchDir(const std::string& name) {
  const fs::path dir = fs::path(plume::test::tempPath("io_test_" + name));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

SmokeParams smallParams(bool combustion = false) {
  SmokeParams p;
  p.resolution = {12, 10, 8};
  p.cellSize = 0.05f;
  p.origin = {-0.3f, 0.2f, 1.f};
  p.combustion = combustion;
  return p;
}

/// Deterministic, mostly-zero content for every grid, so sparse storage is exercised.
void fillPattern(SmokeSolver& s, float seed) {
  auto fill = [seed](ScalarGrid& g, float scale) {
    const glm::ivec3 n = g.size();
    for (int k = 0; k < n.z; ++k)
      for (int j = 0; j < n.y; ++j)
        for (int i = 0; i < n.x; ++i)
          g(i, j, k) = ((i + 2 * j + 3 * k) % 5 == 0) ? 0.f : scale * (seed + i - 0.5f * j + 0.25f * k);
  };
  fill(s.density(), 0.1f);
  fill(s.soot(), 0.01f);
  fill(s.temperature(), 0.2f);
  fill(s.fuel(), 0.3f);
  fill(s.flame(), 0.4f);
  fill(s.pressure(), -0.5f);
  fill(s.velocity().u(), 1.f);
  fill(s.velocity().v(), -2.f);
  fill(s.velocity().w(), 3.f);
  s.setFrame(int(seed) + 7);
}

bool noTmpFiles(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".tmp") return false;
  return true;
}

TEST(VdbFrame, GridNamesDependOnCombustion) {
  const fs::path dir = scratchDir("names");
  SmokeSolver smoke(smallParams(false));
  fillPattern(smoke, 1.f);
  writeVdbFrame((dir / "smoke.vdb").string(), smoke);
  std::vector<std::string> names = vdbGridNames((dir / "smoke.vdb").string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"density", "temperature", "velocity"}));

  SmokeSolver fire(smallParams(true));
  fillPattern(fire, 1.f);
  writeVdbFrame((dir / "fire.vdb").string(), fire);
  names = vdbGridNames((dir / "fire.vdb").string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"density", "flame", "temperature", "velocity"}));
  EXPECT_TRUE(noTmpFiles(dir));
}

TEST(VdbFrame, RoundTripValuesAndTransform) {
  const fs::path dir = scratchDir("roundtrip");
  const SmokeParams p = smallParams(true);
  SmokeSolver s(p);
  fillPattern(s, 2.f);
  const std::string path = (dir / "frame_0001.vdb").string();
  writeVdbFrame(path, s);
  EXPECT_TRUE(noTmpFiles(dir));

  const DenseGrid d = readVdbGrid(path, "density");
  EXPECT_EQ(d.components, 1);
  EXPECT_FLOAT_EQ(d.voxelSize, p.cellSize);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(d.worldOfVoxelZero[a], p.origin[a] + 0.5f * p.cellSize, 1e-6);
  const glm::ivec3 n = p.resolution;
  // Every cell, inside or outside the stored box, reads back as density + soot.
  auto at = [](const DenseGrid& g, int i, int j, int k, int c) {
    const int x = i - g.min.x, y = j - g.min.y, z = k - g.min.z;
    if (x < 0 || y < 0 || z < 0 || x >= g.size.x || y >= g.size.y || z >= g.size.z) return 0.f;
    return g.values[std::size_t(g.components) *
                        (std::size_t(x) + std::size_t(g.size.x) * (y + std::size_t(g.size.y) * z)) +
                    std::size_t(c)];
  };
  const DenseGrid t = readVdbGrid(path, "temperature");
  const DenseGrid f = readVdbGrid(path, "flame");
  const DenseGrid v = readVdbGrid(path, "velocity");
  EXPECT_EQ(v.components, 3);
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        EXPECT_EQ(at(d, i, j, k, 0), s.density()(i, j, k) + s.soot()(i, j, k));
        EXPECT_EQ(at(t, i, j, k, 0), s.temperature()(i, j, k));
        EXPECT_EQ(at(f, i, j, k, 0), s.flame()(i, j, k));
        // Velocity is stored where there is smoke or flame, and is zero elsewhere.
        const bool visible = s.density()(i, j, k) + s.soot()(i, j, k) != 0.f ||
                             (s.params().combustion && s.flame()(i, j, k) != 0.f);
        const glm::vec3 c = visible ? s.velocity().cellCenter(i, j, k) : glm::vec3(0.f);
        for (int a = 0; a < 3; ++a) EXPECT_EQ(at(v, i, j, k, a), c[a]);
      }
}

TEST(VdbFrame, VelocityEverywhereKeepsClearAir) {
  // [Structural Flames] §6.1: a domain read as a wind field needs its velocity in clear air.
  const fs::path dir = scratchDir("velocity_everywhere");
  SmokeSolver s(smallParams(false));
  fillPattern(s, 2.f);
  s.density().fill(0.f);  // no smoke anywhere: the default frame stores no velocity at all
  s.soot().fill(0.f);
  const std::string masked = (dir / "masked.vdb").string(), full = (dir / "full.vdb").string();
  writeVdbFrame(masked, s);
  writeVdbFrame(full, s, /*velocityEverywhere=*/true);
  EXPECT_EQ(readVdbGrid(masked, "velocity").size, glm::ivec3(0));
  const DenseGrid v = readVdbGrid(full, "velocity");
  const glm::ivec3 n = s.params().resolution;
  // The pattern's velocity is non-zero in the corner cells, so the stored box is the domain.
  ASSERT_EQ(v.min, glm::ivec3(0));
  ASSERT_EQ(v.size, n);
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const glm::vec3 c = s.velocity().cellCenter(i, j, k);
        const std::size_t m = 3 * (std::size_t(i) + std::size_t(n.x) * (j + std::size_t(n.y) * k));
        for (int a = 0; a < 3; ++a) EXPECT_EQ(v.values[m + std::size_t(a)], c[a]);
      }
}

TEST(VdbFrame, UnwritablePathThrowsAndLeavesNoTmp) {
  const fs::path dir = scratchDir("unwritable");
  SmokeSolver s(smallParams());
  const std::string path = (dir / "missing" / "frame.vdb").string();
  try {
    writeVdbFrame(path, s);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  EXPECT_THROW(vdbGridNames(path), std::runtime_error);
  EXPECT_THROW(readVdbGrid(path, "density"), std::runtime_error);
}

TEST(VdbFrame, MissingGridThrows) {
  const fs::path dir = scratchDir("missing_grid");
  SmokeSolver s(smallParams(false));
  const std::string path = (dir / "f.vdb").string();
  writeVdbFrame(path, s);
  EXPECT_THROW(readVdbGrid(path, "flame"), std::runtime_error);
  // An all-zero grid is stored empty and reads back as an empty box.
  const DenseGrid d = readVdbGrid(path, "density");
  EXPECT_EQ(d.size, glm::ivec3(0));
  EXPECT_TRUE(d.values.empty());
}

void expectSameState(SmokeSolver& a, SmokeSolver& b) {
  EXPECT_EQ(a.frame(), b.frame());
  EXPECT_EQ(a.velocity().u().values(), b.velocity().u().values());
  EXPECT_EQ(a.velocity().v().values(), b.velocity().v().values());
  EXPECT_EQ(a.velocity().w().values(), b.velocity().w().values());
  EXPECT_EQ(a.density().values(), b.density().values());
  EXPECT_EQ(a.temperature().values(), b.temperature().values());
  EXPECT_EQ(a.fuel().values(), b.fuel().values());
  EXPECT_EQ(a.soot().values(), b.soot().values());
  EXPECT_EQ(a.flame().values(), b.flame().values());
  EXPECT_EQ(a.pressure().values(), b.pressure().values());
}

TEST(StateFile, RoundTripIsExact) {
  const fs::path dir = scratchDir("state");
  SmokeSolver a(smallParams(true)), b(smallParams(true));
  fillPattern(a, 3.f);
  const std::string path = (dir / "state_0010.bin").string();
  writeState(path, a);
  EXPECT_TRUE(noTmpFiles(dir));
  readState(path, b);
  expectSameState(a, b);
}

std::vector<char> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void writeBytes(const std::string& path, const std::vector<char>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

TEST(StateFile, BadFilesThrowAndLeaveTheSolverUnchanged) {
  const fs::path dir = scratchDir("state_bad");
  SmokeSolver a(smallParams()), b(smallParams()), reference(smallParams());
  fillPattern(a, 3.f);
  fillPattern(b, 5.f);
  fillPattern(reference, 5.f);
  const std::string good = (dir / "good.bin").string();
  writeState(good, a);
  const std::vector<char> bytes = readBytes(good);
  const std::string bad = (dir / "bad.bin").string();

  auto expectRejected = [&](const std::vector<char>& content, const char* what) {
    writeBytes(bad, content);
    try {
      readState(bad, b);
      ADD_FAILURE() << "accepted a " << what << " file";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
    expectSameState(b, reference);
  };
  expectRejected(std::vector<char>(bytes.begin(), bytes.begin() + bytes.size() / 2), "truncated");
  expectRejected(std::vector<char>(bytes.begin(), bytes.begin() + 20), "header-only");
  expectRejected({}, "empty");
  std::vector<char> flipped = bytes;
  flipped[bytes.size() / 2] ^= 0x10;
  expectRejected(flipped, "corrupt");
  std::vector<char> magic = bytes;
  magic[0] = 'X';
  expectRejected(magic, "bad-magic");
  std::vector<char> longer = bytes;
  longer.push_back(0);
  expectRejected(longer, "too-long");
  std::vector<char> huge = bytes;
  huge[55] = char(0xff);  // top byte of the first grid's value count (offset 48)
  expectRejected(huge, "huge-count");

  EXPECT_THROW(readState((dir / "nope.bin").string(), b), std::runtime_error);
  expectSameState(b, reference);

  // Checksum-valid files holding NaN or infinity (written as they are: the checksum is right)
  // are refused by grid name, before they reach the sampling (where NaN became an index).
  for (float bad_value : {std::nanf(""), std::numeric_limits<float>::infinity()}) {
    SmokeSolver poisoned(smallParams());
    fillPattern(poisoned, 3.f);
    poisoned.temperature().values()[17] = bad_value;
    const std::string nan = (dir / "nan.bin").string();
    writeState(nan, poisoned);
    try {
      readState(nan, b);
      ADD_FAILURE() << "accepted a state holding " << bad_value;
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("non-finite"), std::string::npos) << what;
      EXPECT_NE(what.find("'temperature'"), std::string::npos) << what;
      EXPECT_NE(what.find("index 17"), std::string::npos) << what;
    }
    expectSameState(b, reference);
  }

  // A state of another resolution is refused by name.
  SmokeParams other = smallParams();
  other.resolution = {8, 8, 8};
  SmokeSolver c(other);
  try {
    readState(good, c);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos) << e.what();
  }
}

TEST(StateFile, UnwritablePathThrows) {
  const fs::path dir = scratchDir("state_unwritable");
  SmokeSolver s(smallParams());
  const std::string path = (dir / "missing" / "state.bin").string();
  EXPECT_THROW(writeState(path, s), std::runtime_error);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
}

}  // namespace
}  // namespace plume
