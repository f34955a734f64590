/// \file vdb_hostile_test.cpp
/// Hostile VDB files: files made by OpenVDB's own writer (fuzz/vdb_seeds.h), then
/// truncated and changed at every byte of their headers and throughout, given Blosc chunks that claim more than
/// the leaf holds, voxels near 2^30, a NaN voxel size and a grid type that is not UTF-8. Every
/// VDB reader of Plume either reads the file or throws std::runtime_error naming the file in
/// clean UTF-8; nothing crashes (run under AddressSanitizer: no write or read out of bounds).

#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "fuzz/vdb_seeds.h"
#include "io/mantaflow_cache.h"
#include "io/utf8_text.h"
#include "io/vdb_frame.h"

namespace plume {
namespace {

using Bytes = std::vector<unsigned char>;

/// A file name of this process: ctest runs the tests of this file in parallel processes, which
/// must not write (and rename onto) the same path.
std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "plume_hostile_" + std::to_string(::getpid()) + "_" + name;
}

Bytes load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}

void save(const std::string& path, const Bytes& b, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(b.data()), std::streamsize(size));
}

/// Reads `path` with every VDB reader. Each must read it or throw std::runtime_error whose
/// message names the file and is clean UTF-8 (any other exception fails the test). Returns the
/// number of readers that refused it.
int readAll(const std::string& path) {
  int refused = 0;
  const auto attempt = [&](const std::function<void()>& read) {
    try {
      read();
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path), std::string::npos) << what;
      EXPECT_EQ(cleanUtf8(what), what) << "not clean UTF-8";
      ++refused;
    }
  };
  attempt([&] { vdbGridNames(path); });
  for (const char* name : {"density", "velocity", "temperature"})
    attempt([&] { readVdbGrid(path, name); });
  attempt([&] { readMantaflowFrame(path, seeds::mantaflowGrid()); });
  return refused;
}

struct Seed {
  std::string name;
  Bytes bytes;
};

/// Positions to damage in a seed of `size` bytes (about 30 kB, mostly node masks): every one of
/// the first 640 (header, descriptors, metadata, transform, root of the first grid), every
/// `stride`-th after, and the last 16 (the end of the last leaf buffer).
std::vector<std::size_t> positions(std::size_t size, std::size_t stride) {
  std::vector<std::size_t> p;
  for (std::size_t k = 0; k < size; k += k < 640 ? 1 : stride) p.push_back(k);
  for (std::size_t k = size > 16 ? size - 16 : 0; k < size; ++k) p.push_back(k);
  return p;
}

std::vector<Seed> makeSeeds() {
  std::vector<Seed> seeds;
  const std::string path = tempPath("seed.vdb");
  seeds::writeMantaflowSeed(path, /*half=*/false);
  seeds.push_back({"mantaflow", load(path)});
  seeds::writeMantaflowSeed(path, /*half=*/true);
  seeds.push_back({"mantaflow half", load(path)});
  seeds::writePlumeFrameSeed(path);
  seeds.push_back({"plume frame", load(path)});
  std::remove(path.c_str());
  return seeds;
}

TEST(VdbHostile, SeedsReadAndHalfFloatsMatch) {
  const MantaflowGrid g = seeds::mantaflowGrid();
  const std::vector<Seed> all = makeSeeds();
  const std::string path = tempPath("good.vdb");
  save(path, all[0].bytes, all[0].bytes.size());
  EXPECT_EQ(readAll(path), 0);
  const MantaflowFrame full = readMantaflowFrame(path, g);
  save(path, all[1].bytes, all[1].bytes.size());
  EXPECT_EQ(readAll(path), 0);
  const MantaflowFrame half = readMantaflowFrame(path, g);
  // Half floats keep 11 significant bits: relative error below 2^-11.
  for (std::size_t m = 0; m < full.density.count(); ++m)
    EXPECT_NEAR(half.density[m], full.density[m], std::abs(full.density[m]) * 4.9e-4f);
  EXPECT_GT(full.density(2, 3, 1), 0.f);
  save(path, all[2].bytes, all[2].bytes.size());
  EXPECT_EQ(vdbGridNames(path), (std::vector<std::string>{"density", "temperature", "velocity"}));
  EXPECT_EQ(readVdbGrid(path, "velocity").components, 3);
  std::remove(path.c_str());
}

TEST(VdbHostile, TruncatedFilesAreRefusedByEveryReader) {
  const std::string path = tempPath("short.vdb");
  for (const Seed& s : makeSeeds())
    for (const std::size_t size : positions(s.bytes.size(), 61)) {
      save(path, s.bytes, size);
      // The last grid ends at the end of the file: every reader sees the file is short.
      ASSERT_EQ(readAll(path), 5) << s.name << " cut to " << size << " bytes";
    }
  std::remove(path.c_str());
}

TEST(VdbHostile, ChangedBytesAreReadOrRefusedCleanly) {
  const std::string path = tempPath("changed.vdb");
  for (Seed& s : makeSeeds()) {
    int refusals = 0;
    const std::vector<std::size_t> changed = positions(s.bytes.size(), 151);
    for (const std::size_t p : changed) {
      const unsigned char original = s.bytes[p];
      s.bytes[p] = std::uint8_t(original ^ (p % 2 ? 0xff : 0x80));
      save(path, s.bytes, s.bytes.size());
      refusals += readAll(path) > 0 ? 1 : 0;
      s.bytes[p] = original;
    }
    EXPECT_GT(refusals, int(changed.size()) / 2) << s.name;  // most bytes matter
  }
  std::remove(path.c_str());
}

std::int64_t int64At(const Bytes& b, std::size_t p) {
  std::int64_t v;
  std::memcpy(&v, b.data() + p, 8);
  return v;
}

std::uint32_t uint32At(const Bytes& b, std::size_t p) {
  std::uint32_t v;
  std::memcpy(&v, b.data() + p, 4);
  return v;
}

/// OpenVDB 10.0.1 reads -n bytes of a chunk stored uncompressed (size field -n) into the leaf
/// buffer before comparing n with its size, and lets Blosc decompress from a buffer of the
/// length the file claims. Each Blosc chunk of the seeds (size field n, then a Blosc header
/// whose cbytes is n) is changed three ways; every change must be refused.
TEST(VdbHostile, ChunksClaimingMoreThanTheLeafHoldsAreRefused) {
  const std::string path = tempPath("chunk.vdb");
  for (const Seed& s : makeSeeds()) {
    int chunks = 0, refused[3] = {0, 0, 0};
    for (std::size_t p = 0; p + 8 + 16 <= s.bytes.size(); ++p) {
      const std::int64_t n = int64At(s.bytes, p);
      if (!(n >= 16 && n < 65536 && s.bytes[p + 8] == 2 &&
            uint32At(s.bytes, p + 8 + 12) == std::uint64_t(n)))
        continue;
      ++chunks;
      const std::uint32_t nbytes = uint32At(s.bytes, p + 8 + 4);
      for (int change = 0; change < 3; ++change) {
        Bytes b = s.bytes;
        if (change == 0) {  // the Blosc header claims 4096 more decompressed bytes
          const std::uint32_t more = nbytes + 4096;
          std::memcpy(b.data() + p + 8 + 4, &more, 4);
        } else if (change == 1) {  // stored uncompressed, 256 bytes more than the leaf holds
          const std::int64_t raw = -std::int64_t(nbytes) - 256;
          std::memcpy(b.data() + p, &raw, 8);
        } else {  // one changed byte: the size's top byte makes it negative (-2^63 + n)
          b[p + 7] = 0x80;
        }
        save(path, b, b.size());
        if (readAll(path) > 0) ++refused[change];
      }
    }
    EXPECT_GE(chunks, 3) << s.name;
    for (int change = 0; change < 3; ++change) EXPECT_EQ(refused[change], chunks) << s.name;
  }
  std::remove(path.c_str());
}

/// OpenVDB takes the tree's half-float flag from the grid metadata is_saved_as_half_float, read
/// after the descriptor: a file whose metadata says "half" for a full-precision tree would be
/// read with the wrong value size (found by fuzz_mantaflow: a 25 GB Blosc allocation). The flag
/// of the descriptor, the one the tree is checked with, is the one OpenVDB gets.
TEST(VdbHostile, HalfFloatMetadataCannotChangeHowTheTreeIsRead) {
  const std::string path = tempPath("halfmeta.vdb");
  for (const bool half : {false, true}) {
    seeds::writeMantaflowSeed(path, half);
    Bytes b = load(path);
    const std::string name = "is_saved_as_half_float";
    int changed = 0;
    for (auto at = b.begin(); (at = std::search(at, b.end(), name.begin(), name.end())) != b.end();
         ++at) {
      // name, then the type "bool" (u32 length + 4 bytes), the size (u32), the value byte.
      b[std::size_t(at - b.begin()) + name.size() + 4 + 4 + 4] = half ? 0 : 1;
      ++changed;
    }
    ASSERT_EQ(changed, 3);
    save(path, b, b.size());
    EXPECT_EQ(readAll(path), 0) << half;
  }
  std::remove(path.c_str());
}

TEST(VdbHostile, VoxelsNearTwoToTheThirtyAreRefused) {
  openvdb::initialize();
  const std::string path = tempPath("far.vdb");
  for (const int far : {1 << 30, (1 << 30) + 4095, 2147483647 - 8, -2147483647, 1 << 21}) {
    auto d = openvdb::FloatGrid::create(0.f);
    d->tree().setValue(openvdb::Coord(0, 0, 0), 1.f);
    d->tree().setValue(openvdb::Coord(far, 1, far), 1.f);
    d->setName("density");
    openvdb::io::File file(path);
    file.write({d});
    file.close();
    try {
      readVdbGrid(path, "density");
      ADD_FAILURE() << "read a grid reaching " << far;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
    EXPECT_EQ(readAll(path), 4) << far;  // all but the names: density refused, the rest missing
  }
  std::remove(path.c_str());
}

TEST(VdbHostile, VoxelSizeThatIsNotFiniteIsRefused) {
  const std::string path = tempPath("nan.vdb");
  seeds::writeMantaflowSeed(path, false);
  const Bytes seed = load(path);
  const double voxel = double(seeds::mantaflowGrid().vdbVoxelSize());
  for (const double bad : {std::nan(""), HUGE_VAL, 0.0}) {
    Bytes b = seed;
    int replaced = 0;
    for (std::size_t p = 0; p + 8 <= b.size(); ++p)
      if (std::memcmp(b.data() + p, &voxel, 8) == 0) {
        std::memcpy(b.data() + p, &bad, 8);
        ++replaced;
      }
    ASSERT_GE(replaced, 3);  // scale and voxel size of each of the three grids
    save(path, b, b.size());
    EXPECT_EQ(readAll(path), 4) << bad;  // every grid read; the names stay readable
  }
  std::remove(path.c_str());
}

TEST(VdbHostile, NamesAndTypesThatAreNotUtf8GiveCleanMessages) {
  const std::string path = tempPath("utf8.vdb");
  seeds::writeMantaflowSeed(path, false);
  Bytes b = load(path);
  const std::string type = "Tree_float_5_4_3";
  const auto at = std::search(b.begin(), b.end(), type.begin(), type.end());
  ASSERT_NE(at, b.end());
  *at = 0xff;  // the density grid's type
  save(path, b, b.size());
  try {
    readVdbGrid(path, "density");
    ADD_FAILURE() << "read a grid of type \\xffree_float_5_4_3";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("\\xffree_float_5_4_3"), std::string::npos) << what;
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_EQ(cleanUtf8(what), what);
  }
  EXPECT_GE(readAll(path), 2);
  // A grid name that is not UTF-8 is listed escaped, and found by that name.
  seeds::writePlumeFrameSeed(path);
  b = load(path);
  const std::string name = "temperature";
  const auto n = std::search(b.begin(), b.end(), name.begin(), name.end());
  ASSERT_NE(n, b.end());
  *n = 0xc3;  // a lead byte followed by ASCII: not UTF-8
  save(path, b, b.size());
  const std::vector<std::string> names = vdbGridNames(path);
  ASSERT_EQ(names.size(), 3u);
  EXPECT_EQ(names[2], "\\xc3emperature");
  EXPECT_EQ(readVdbGrid(path, names[2]).components, 1);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace plume
