/// \file flowgraph_synth_test.cpp
/// Flow-graph fire synthesis ([Graph Fire Synthesis] §4.2, §5.2): the pathline file, the
/// synthesizer (eq. 13) and grid external velocities. RK4 pathlines are in
/// flowgraph_pathlines_test.cpp, the rasterization in fire_raster_test.cpp, the reproduction of
/// a real bake by a temporal walk in flowgraph_reproduction_test.cpp.

#include "core/parallel.h"
#include "core/rng.h"
#include "fields/fire_raster.h"
#include "flowgraph/pathline_integrator.h"
#include "flowgraph/pathline_recorder.h"
#include "flowgraph/synthesizer.h"
#include "fields/velocity_field.h"
#include "flowgraph/pathline_file.h"
#include "io/vdb_frame.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <stdexcept>
#include "tests/temp_path.h"

namespace fs = std::filesystem;

namespace plume {
namespace {

// --- pathline files -----------------------------------------------------------------------

PathlineGroup randomGroup(const PathlineLayout& layout, int step, std::uint64_t seed) {
  PathlineGroup g;
  g.step = step;
  g.layout = layout;
  Rng rng(seed);
  auto r = [&](double lo, double hi) { return float(lo + (hi - lo) * rng.uniform()); };
  g.start.resize(std::size_t(layout.particles));
  for (auto& x : g.start) x = glm::vec3(r(0, 1), r(0, 1), r(0, 1));
  const std::size_t v = layout.values();
  g.velocity.resize(v);
  g.density.resize(v);
  g.temperature.resize(v);
  for (std::size_t n = 0; n < v; ++n) {
    g.velocity[n] = glm::vec3(r(-3, 3), r(-3, 3), r(-1, 8));
    g.density[n] = n % 7 == 0 ? 0.f : r(0, 2);
    g.temperature[n] = r(0, 5);
  }
  return g;
}

PathlineFileInfo fileInfo(const PathlineLayout& layout, bool half) {
  PathlineFileInfo info;
  info.layout = layout;
  info.resolution = glm::ivec3(24, 20, 32);
  info.cellSize = 0.05f;
  info.origin = glm::vec3(-0.5f, 0.25f, 0.f);
  info.nodesPerFrame = 2;
  info.float16 = half;
  return info;
}

std::string tempPath(const std::string& name) { return plume::test::tempPath("pathlines_" + name); }

/// Writes `count` random groups; returns them.
std::vector<PathlineGroup> writeGroups(const std::string& path, const PathlineFileInfo& info, int count) {
  std::vector<PathlineGroup> groups;
  PathlineFileWriter w(path, info);
  for (int k = 0; k < count; ++k) {
    groups.push_back(randomGroup(info.layout, k, std::uint64_t(k) + 11));
    w.append(groups.back());
  }
  w.finish();
  return groups;
}

void expectThrowsNaming(const std::function<void()>& f, const std::string& path, const std::string& what) {
  try {
    f();
    ADD_FAILURE() << "no error for " << path;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
  }
}

TEST(PathlineFile, RoundTripIsExactInFloat32) {
  const PathlineLayout layout{37, 9, 1.f / 48.f};
  const std::string path = tempPath("f32.bin");
  const auto groups = writeGroups(path, fileInfo(layout, false), 5);
  EXPECT_FALSE(fs::exists(path + ".partial"));
  const PathlineFile f = PathlineFile::open(path);
  EXPECT_EQ(f.nodeCount(), 5);
  EXPECT_TRUE(f.layout() == layout);
  EXPECT_EQ(f.info().resolution, glm::ivec3(24, 20, 32));
  EXPECT_EQ(f.info().origin, glm::vec3(-0.5f, 0.25f, 0.f));
  EXPECT_EQ(f.info().nodesPerFrame, 2);
  for (int k : {3, 0, 4}) {
    const PathlineGroup g = f.readGroup(k, /*state=*/2);
    EXPECT_EQ(g.state, 2);
    EXPECT_EQ(g.step, k);
    EXPECT_EQ(g.start, groups[std::size_t(k)].start);
    EXPECT_EQ(g.velocity, groups[std::size_t(k)].velocity);
    EXPECT_EQ(g.density, groups[std::size_t(k)].density);
    EXPECT_EQ(g.temperature, groups[std::size_t(k)].temperature);
  }
  EXPECT_EQ(fs::file_size(path), 80 + 5 * f.bytesPerNode() + 16 * 5 + 8);
  EXPECT_THROW(f.readGroup(5), std::out_of_range);
  // The size the synthesis budget is set for: |Ω| = 3,200, L = 48.
  PathlineFileInfo big = fileInfo(PathlineLayout{3200, 48, 1.f / 48.f}, false);
  std::cout << "bytes per node (3200 pathlines, 48 samples): float32 " << big.blockBytes();
  big.float16 = true;
  std::cout << ", float16 " << big.blockBytes() << "\n";
}

TEST(PathlineFile, HalfPrecisionRoundsToNearest) {
  // Every finite half survives float -> half -> float; floats round within half an ulp (2^-11
  // relative for normal halves, 2^-25 absolute below them).
  for (std::uint32_t b = 0; b < 0x10000u; ++b) {
    if ((b & 0x7c00u) == 0x7c00u) continue;  // inf / NaN
    const float f = halfToFloat(std::uint16_t(b));
    ASSERT_EQ(halfToFloat(floatToHalf(f)), f) << b;
  }
  Rng rng(3);
  for (int n = 0; n < 100000; ++n) {
    const float f = float((rng.uniform() - 0.5) * std::pow(2.0, 30.0 * rng.uniform() - 20.0));
    const float back = halfToFloat(floatToHalf(f));
    ASSERT_LE(std::fabs(back - f), std::fabs(f) * 0x1p-11f + 0x1p-25f) << f;
  }
  EXPECT_EQ(halfToFloat(floatToHalf(1e9f)), 65504.f);  // clamped, not infinite
  EXPECT_EQ(halfToFloat(floatToHalf(NAN)), 0.f);
}

TEST(PathlineFile, Float16RoundTripWithinHalfRounding) {
  const PathlineLayout layout{20, 6, 0.02f};
  const std::string path = tempPath("f16.bin");
  const auto groups = writeGroups(path, fileInfo(layout, true), 3);
  const PathlineFile f = PathlineFile::open(path);
  EXPECT_TRUE(f.info().float16);
  const PathlineGroup g = f.readGroup(1);
  const PathlineGroup& w = groups[1];
  EXPECT_EQ(g.start, w.start);  // positions stay float32
  auto close = [](float a, float b) { return std::fabs(a - b) <= std::fabs(b) * 0x1p-11f + 0x1p-25f; };
  for (std::size_t n = 0; n < layout.values(); ++n) {
    for (int c = 0; c < 3; ++c) ASSERT_TRUE(close(g.velocity[n][c], w.velocity[n][c]));
    ASSERT_TRUE(close(g.density[n], w.density[n]));
    ASSERT_TRUE(close(g.temperature[n], w.temperature[n]));
  }
  PathlineFileInfo f32 = f.info();
  f32.float16 = false;
  EXPECT_LT(f.bytesPerNode(), f32.blockBytes());
}

void corruptByte(const std::string& path, std::uint64_t at) {
  std::fstream io(path, std::ios::binary | std::ios::in | std::ios::out);
  io.seekg(std::streamoff(at));
  char c;
  io.read(&c, 1);
  c = char(c ^ 0x5a);
  io.seekp(std::streamoff(at));
  io.write(&c, 1);
}

TEST(PathlineFile, TruncatedOrCorruptFilesNameTheFile) {
  const PathlineLayout layout{10, 4, 0.05f};
  const PathlineFileInfo info = fileInfo(layout, false);
  const std::string path = tempPath("bad.bin");
  writeGroups(path, info, 3);
  const auto size = fs::file_size(path);
  expectThrowsNaming([&] { PathlineFile::open(tempPath("missing.bin")); }, tempPath("missing.bin"),
                     "cannot be opened");
  fs::resize_file(path, size - 5);
  expectThrowsNaming([&] { PathlineFile::open(path); }, path, "truncated");
  fs::resize_file(path, 40);
  expectThrowsNaming([&] { PathlineFile::open(path); }, path, "truncated");
  writeGroups(path, info, 3);
  corruptByte(path, 20);  // the header
  expectThrowsNaming([&] { PathlineFile::open(path); }, path, "corrupt");
  writeGroups(path, info, 3);
  corruptByte(path, size - 12);  // the table
  expectThrowsNaming([&] { PathlineFile::open(path); }, path, "corrupt");
  writeGroups(path, info, 3);
  corruptByte(path, 80 + info.blockBytes() + 100);  // node 1
  const PathlineFile f = PathlineFile::open(path);  // the table is fine
  EXPECT_NO_THROW(f.readGroup(0));
  expectThrowsNaming([&] { f.readGroup(1); }, path, "corrupt");
  std::ofstream(path, std::ios::binary | std::ios::trunc) << std::string(200, 'x');
  expectThrowsNaming([&] { PathlineFile::open(path); }, path, "bad magic");
}

TEST(PathlineFile, NonFiniteSamplesAreRefusedByName) {
  // Checksum-valid files holding NaN or infinity: synthesized particles would move to
  // non-finite positions that become cell indices.
  const PathlineLayout layout{10, 4, 0.05f};
  const std::string path = tempPath("nonfinite.bin");
  {  // float32: the writer stores the values as given
    PathlineFileWriter w(path, fileInfo(layout, false));
    w.append(randomGroup(layout, 0, 1));
    PathlineGroup g = randomGroup(layout, 1, 2);
    g.velocity[7].y = std::numeric_limits<float>::quiet_NaN();
    w.append(g);
    g = randomGroup(layout, 2, 3);
    g.temperature[39] = std::numeric_limits<float>::infinity();
    w.append(g);
    w.finish();
  }
  const PathlineFile f = PathlineFile::open(path);
  EXPECT_NO_THROW(f.readGroup(0));
  expectThrowsNaming([&] { f.readGroup(1); }, path, "node 1 holds a non-finite value");
  expectThrowsNaming([&] { f.readGroup(2); }, path, "node 2 holds a non-finite value");

  // float16: the writer never stores NaN or infinity (it clamps), so set the bits of a density
  // sample of node 0 to +inf (0x7c00) and re-sign the block and the table.
  const PathlineFileInfo info = fileInfo(layout, true);
  writeGroups(path, info, 1);
  std::vector<unsigned char> bytes(fs::file_size(path));
  std::ifstream(path, std::ios::binary).read(reinterpret_cast<char*>(bytes.data()),
                                              std::streamsize(bytes.size()));
  const std::size_t block = info.blockBytes(), density = 80 + 8 + 12 * 10 + 2 * 3 * 40;
  bytes[density + 2 * 5] = 0x00;
  bytes[density + 2 * 5 + 1] = 0x7c;
  const std::size_t table = 80 + block;
  const std::uint64_t blockSum = pathlineChecksum(bytes.data() + 80, block);
  for (int b = 0; b < 8; ++b) bytes[table + 8 + std::size_t(b)] = (blockSum >> (8 * b)) & 0xff;
  const std::uint64_t tableSum = pathlineChecksum(bytes.data() + table, 16);
  for (int b = 0; b < 8; ++b) bytes[table + 16 + std::size_t(b)] = (tableSum >> (8 * b)) & 0xff;
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  const PathlineFile h = PathlineFile::open(path);
  expectThrowsNaming([&] { h.readGroup(0); }, path, "node 0 holds a non-finite value");
}

TEST(PathlineFile, UnfinishedWriteNeverReadsAsComplete) {
  const PathlineLayout layout{10, 4, 0.05f};
  const std::string path = tempPath("killed.bin");
  writeGroups(path, fileInfo(layout, false), 2);  // an older complete file
  {
    // A bake killed after two groups: the writer never reaches finish() (its destructor leaves
    // the file as a kill would).
    PathlineFileWriter w(path, fileInfo(layout, false));
    EXPECT_FALSE(fs::exists(path));  // the older file is gone: it belonged to the replaced bake
    w.append(randomGroup(layout, 0, 1));
    w.append(randomGroup(layout, 1, 2));
  }
  EXPECT_FALSE(fs::exists(path));
  ASSERT_TRUE(fs::exists(path + ".partial"));
  // Even under the final name, the partial file says it is incomplete.
  fs::copy_file(path + ".partial", path);
  expectThrowsNaming([&] { PathlineFile::open(path); }, path, "incomplete");
  fs::remove(path);
  {
    PathlineFileWriter w(path, fileInfo(layout, false));
    w.append(randomGroup(layout, 0, 1));
    EXPECT_THROW(w.append(randomGroup(layout, 5, 1)), std::invalid_argument);  // not node 1
    w.discard();
  }
  EXPECT_FALSE(fs::exists(path + ".partial"));
  EXPECT_FALSE(fs::exists(path));
}

// --- synthesizer ----------------------------------------------------------------------------

/// A group whose particle p moves with u(t) = a_p + t b (t = local time), samples exact.
PathlineGroup linearGroup(const PathlineLayout& layout, int step, glm::vec3 b) {
  PathlineGroup g = randomGroup(layout, step, std::uint64_t(step) + 100);
  for (int p = 0; p < layout.particles; ++p)
    for (int s = 0; s < layout.samples; ++s)
      g.velocity[g.index(p, s)] = glm::vec3(0.1f * float(p), -0.2f, 1.f + float(step)) +
                                  float(s) * layout.sampleDt * b;
  return g;
}

TEST(Synthesizer, ParticlesFollowTheirOwnPathlineAndDie) {
  // Velocity linear in time: the trapezoid rule (eq. 13) is exact. Node 5 is visited after node
  // 0 (a transition): the particles of node 0 keep following node 0's pathlines.
  const PathlineLayout layout{7, 5, 0.1f};
  const glm::vec3 b(0.5f, 0.f, -1.f), wind(0.2f, 0.f, 0.f);
  std::vector<PathlineGroup> nodes;
  for (int k = 0; k < 8; ++k) nodes.push_back(linearGroup(layout, k, b));
  Synthesizer s(layout);
  const int walk[] = {0, 5, 6, 2, 3, 4, 7};
  SynthParticles out;
  for (int n = 0; n < 7; ++n) {
    s.step(nodes[std::size_t(walk[n])], wind);
    EXPECT_EQ(s.liveGroups(), std::min(n + 1, layout.samples));
    s.gather(out);
    ASSERT_EQ(out.size(), s.particleCount());
    for (int gi = 0; gi < s.liveGroups(); ++gi) {
      const long long e = s.firstLiveStep() + gi;
      const PathlineGroup& g = nodes[std::size_t(walk[e])];
      const int age = int(s.steps() - 1 - e);
      const float t = float(age) * layout.sampleDt;
      for (int p = 0; p < layout.particles; ++p) {
        const std::size_t i = std::size_t(gi * layout.particles + p);
        const glm::vec3 a = g.velocity[g.index(p, 0)];
        const glm::vec3 exact = g.start[std::size_t(p)] + t * a + 0.5f * t * t * b + t * wind;
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(out.positions[i][c], exact[c], 1e-5f);
        ASSERT_EQ(out.density[i], g.density[g.index(p, age)]);
        ASSERT_EQ(out.temperature[i], g.temperature[g.index(p, age)]);
      }
    }
  }
  // Lifetime L = 5 samples: after 7 steps the groups of steps 0 and 1 are gone.
  EXPECT_EQ(s.firstLiveStep(), 2);
  PathlineGroup wrong = nodes[0];
  wrong.layout.samples = 4;
  EXPECT_THROW(s.step(wrong), std::invalid_argument);
}

/// u_ext = c + K x (a constant plus a shear), for the field path.
struct ShearField final : ExternalVelocity {
  glm::vec3 c{0.f};
  float k = 0.f;
  void evaluate(const glm::vec3* x, int n, double, glm::vec3* out) const override {
    for (int m = 0; m < n; ++m) out[m] = c + glm::vec3(k * x[m].z, 0.f, 0.f);
  }
};

TEST(Synthesizer, ExternalFieldsIntegrateWithHeun) {
  const PathlineLayout layout{600, 6, 0.05f};  // two parallel chunks
  std::vector<PathlineGroup> nodes;
  for (int k = 0; k < 9; ++k) nodes.push_back(linearGroup(layout, k, glm::vec3(0.f)));
  // A constant field equals the uniform velocity (Heun is exact for it).
  ShearField constant;
  constant.c = glm::vec3(0.3f, -0.1f, 0.2f);
  Synthesizer a(layout), b(layout);
  SynthParticles pa, pb;
  for (const auto& g : nodes) {
    a.step(g, constant.c);
    b.step(g, constant);
  }
  a.gather(pa);
  b.gather(pb);
  for (std::size_t n = 0; n < pa.size(); ++n)
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(pa.positions[n][c], pb.positions[n][c], 1e-5f);
  // One step of a shear u_x = k z with the pathline moving z at w: Heun gives
  // Δx = h k (z + (z + h w)) / 2, exact since u_ext is linear along the straight step.
  ShearField shear;
  shear.k = 2.f;
  Synthesizer c(layout);
  c.step(nodes[0]);
  c.step(nodes[1], shear);
  SynthParticles pc;
  c.gather(pc);
  const PathlineGroup& g = nodes[0];
  const float h = layout.sampleDt;
  for (int p = 0; p < layout.particles; ++p) {
    const glm::vec3 x0 = g.start[std::size_t(p)];
    const float w = g.velocity[g.index(p, 0)].z;
    const float expected = x0.x + h * g.velocity[g.index(p, 0)].x + h * shear.k * (x0.z + 0.5f * h * w);
    ASSERT_NEAR(pc.positions[std::size_t(p)].x, expected, 1e-5f);
  }
}

TEST(Synthesizer, EmitterTransformPlacesGroupsAtEmission) {
  // The fire blade (§5.2): a group emitted under placement E starts at E x_0 and then moves as
  // its pathline does in world space (rotation does not turn its velocity); groups keep the
  // placement of their emission when E changes afterwards (a swung source trails fire).
  const PathlineLayout layout{600, 6, 0.05f};
  std::vector<PathlineGroup> nodes;
  for (int k = 0; k < 6; ++k) nodes.push_back(randomGroup(layout, k, std::uint64_t(k) + 3));
  glm::mat4 placements[6];
  for (int k = 0; k < 6; ++k) {  // a quarter turn about z over the steps, moving along x
    const float angle = 0.3f * float(k), c = std::cos(angle), sn = std::sin(angle);
    placements[k] = glm::mat4(1.f);
    placements[k][0] = glm::vec4(c, sn, 0.f, 0.f);
    placements[k][1] = glm::vec4(-sn, c, 0.f, 0.f);
    placements[k][3] = glm::vec4(0.4f * float(k), -0.2f, 0.1f, 1.f);
  }
  ShearField shear;
  shear.k = 0.5f;
  Synthesizer plain(layout), placed(layout);
  for (int k = 0; k < 6; ++k) {
    placed.setEmitterTransform(placements[k]);
    if (k == 3) {  // the field path (Heun) sees the placed positions
      plain.step(nodes[std::size_t(k)], glm::vec3(0.2f, 0.f, 0.f));
      placed.step(nodes[std::size_t(k)], glm::vec3(0.2f, 0.f, 0.f));
    } else {
      plain.step(nodes[std::size_t(k)], glm::vec3(0.f, 0.1f, 0.f));
      placed.step(nodes[std::size_t(k)], glm::vec3(0.f, 0.1f, 0.f));
    }
  }
  SynthParticles a, b;
  plain.gather(a);
  placed.gather(b);
  ASSERT_EQ(a.size(), b.size());
  for (int gi = 0; gi < 6; ++gi)
    for (int p = 0; p < layout.particles; ++p) {
      const std::size_t i = std::size_t(gi * layout.particles + p);
      const glm::vec3 x0 = nodes[std::size_t(gi)].start[std::size_t(p)];
      const glm::vec3 shift = glm::vec3(placements[gi] * glm::vec4(x0, 1.f)) - x0;
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(b.positions[i][c], a.positions[i][c] + shift[c], 1e-5f) << gi;
      ASSERT_EQ(b.velocity[i], a.velocity[i]);  // world-space motion, not rotated
      ASSERT_EQ(b.density[i], a.density[i]);
    }
  // A field u_ext is integrated where the placed particles are: with a shear u_x = k z, a
  // placement that lifts the group by dz adds k dz h per step.
  Synthesizer lifted(layout), ground(layout);
  glm::mat4 up(1.f);
  up[3] = glm::vec4(0.f, 0.f, 1.f, 1.f);
  lifted.setEmitterTransform(up);
  for (Synthesizer* s : {&lifted, &ground}) {
    s->step(nodes[0]);
    s->step(nodes[1], shear);
  }
  lifted.gather(a);
  ground.gather(b);
  for (int p = 0; p < layout.particles; ++p)
    ASSERT_NEAR(a.positions[std::size_t(p)].x - b.positions[std::size_t(p)].x, shear.k * 1.f * layout.sampleDt, 1e-5f);
  glm::mat4 bad(1.f);
  bad[0][3] = 0.5f;
  EXPECT_THROW(lifted.setEmitterTransform(bad), std::invalid_argument);
  bad = glm::mat4(1.f);
  bad[3][0] = std::nanf("");
  EXPECT_THROW(lifted.setEmitterTransform(bad), std::invalid_argument);
}

TEST(Synthesizer, BitIdenticalAtOneAndTwoThreads) {
  const PathlineLayout layout{1500, 8, 0.05f};
  std::vector<PathlineGroup> nodes;
  for (int k = 0; k < 4; ++k) nodes.push_back(randomGroup(layout, k, std::uint64_t(k) + 7));
  ShearField shear;
  shear.k = 0.7f;
  SynthParticles out[2];
  for (int t = 0; t < 2; ++t) {
    Synthesizer s(layout, t + 1);
    for (int n = 0; n < 12; ++n) {
      if (n % 3 == 0) s.step(nodes[std::size_t(n % 4)], shear);
      else s.step(nodes[std::size_t(n % 4)], glm::vec3(0.1f, 0.f, 0.f));
    }
    s.gather(out[t]);
  }
  EXPECT_EQ(out[0].positions, out[1].positions);
  EXPECT_EQ(out[0].density, out[1].density);
  EXPECT_EQ(out[0].temperature, out[1].temperature);
}

TEST(GridVelocityField, TrilinearInsideClampedOutside) {
  // u = (x + 2y, -z, 3): linear, so trilinear sampling is exact between cell centres.
  const float h = 0.25f;
  const glm::vec3 origin(-1.f, 0.f, 0.5f);
  VectorGrid g(glm::ivec3(5, 4, 6));
  auto exact = [&](glm::vec3 x) { return glm::vec3(x.x + 2.f * x.y, -x.z, 3.f); };
  for (int k = 0; k < 6; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 5; ++i) g(i, j, k) = exact(origin + (glm::vec3(i, j, k) + 0.5f) * h);
  const GridVelocityField f(g, h, origin);
  const glm::vec3 inside = origin + glm::vec3(0.7f, 0.61f, 1.2f);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(f.at(inside)[c], exact(inside)[c], 1e-5f);
  // Beyond the last centre the nearest values hold.
  const glm::vec3 below = origin + glm::vec3(-5.f, 0.125f, 0.125f);
  EXPECT_EQ(f.at(below), g(0, 0, 0));
  glm::vec3 out[2];
  const glm::vec3 x[2] = {inside, below};
  f.evaluate(x, 2, 0.0, out);
  EXPECT_EQ(out[1], g(0, 0, 0));
  EXPECT_THROW(GridVelocityField(g, 0.f, origin), std::invalid_argument);
  g(1, 1, 1).x = NAN;
  EXPECT_THROW(GridVelocityField(g, h, origin), std::invalid_argument);
}

}  // namespace
}  // namespace plume
