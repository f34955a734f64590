// The cubic passes skip the runs whose traced points all fall in cells with an all-background
// stencil (CleanStencils, solver/block_mask.h): on a sparse field, mostly clean air with a few
// blobs and some -0 samples (a different bit pattern from the background 0), every scheme must
// still give its textbook formula bit for bit, with and without a block mask (which also limits
// the stencil tests to the blocks around the active ones).
#include "core/rng.h"
#include "solver/advection.h"
#include "solver/block_mask.h"

#include <gtest/gtest.h>

#include <cstring>

namespace plume {
namespace {

/// Zeros with one or two blobs of random values and a patch of -0 samples.
ScalarGrid sparseField(glm::ivec3 n, std::uint64_t seed, bool second) {
  Rng rng(seed);
  ScalarGrid g(n);
  g.fill(0.f);
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const bool blobA = i >= 3 && i < 7 && j >= 4 && j < 8 && k >= 3 && k < 6;
        const bool blobB = second && i >= 22 && i < 25 && j >= 14 && j < 17 && k >= 10 && k < 12;
        if (blobA || blobB) g(i, j, k) = float(rng.uniform(0.0, 1.0));
        if (i >= 14 && i < 17 && j < 3 && k < 3) g(i, j, k) = -0.f;
      }
  return g;
}

/// The scheme's formulas on the position-based samplers and traceBack() (as the reference of
/// advection_test.cpp).
ScalarGrid reference(const MacGrid3& velocity, const ScalarGrid& phi, float cells,
                     Advection scheme) {
  const glm::ivec3 n = phi.size();
  const glm::vec3 offset = kCellOffset;
  auto at = [&](const ScalarGrid& g, glm::vec3 q) { return sampleMonotonicCubic(g, q); };
  auto trace = [&](int i, int j, int k, float c) {
    return traceBack(velocity, glm::vec3(i, j, k) + offset, c) - offset;
  };
  auto each = [&](ScalarGrid& out, const auto& value) {
    out.resize(n);
    for (int k = 0; k < n.z; ++k)
      for (int j = 0; j < n.y; ++j)
        for (int i = 0; i < n.x; ++i) out(i, j, k) = value(i, j, k);
  };
  auto clamped = [&](float value, glm::vec3 q) {
    float lo, hi;
    sampleRange(phi, q, lo, hi);
    return value < lo ? lo : (value > hi ? hi : value);
  };
  ScalarGrid hat, out, corrected;
  each(hat, [&](int i, int j, int k) { return at(phi, trace(i, j, k, cells)); });
  if (scheme == Advection::SemiLagrangian) return hat;
  if (scheme == Advection::MacCormack) {
    each(out, [&](int i, int j, int k) {
      const float value = hat(i, j, k) + 0.5f * (phi(i, j, k) - at(hat, trace(i, j, k, -cells)));
      return clamped(value, trace(i, j, k, cells));
    });
    return out;
  }
  each(corrected, [&](int i, int j, int k) {
    return phi(i, j, k) + 0.5f * (phi(i, j, k) - at(hat, trace(i, j, k, -cells)));
  });
  each(out, [&](int i, int j, int k) {
    const glm::vec3 q = trace(i, j, k, cells);
    return clamped(at(corrected, q), q);
  });
  return out;
}

/// Every scheme with monotonic cubic samples on `phi` against reference(), bit for bit; with
/// `masked`, in the blocks of a BlockMask of phi (outside them the result is 0 as in phi).
void expectFormulas(glm::ivec3 n, const ScalarGrid& phi, bool masked) {
  Rng rng(7);
  MacGrid3 velocity(n);
  for (int a = 0; a < 3; ++a)
    for (std::size_t c = 0; c < velocity.component(a).count(); ++c)
      velocity.component(a)[c] = float(rng.uniform(-1.5, 1.5));
  const float dt = 0.4f, h = 0.5f;  // at most 2.1 cells a step: within the mask's 16
  BlockMask mask;
  mask.build(phi, 0.f);
  if (masked) ASSERT_LT(mask.fill(), 0.5f);  // most blocks are skipped
  const BlockMask* used = masked ? &mask : nullptr;
  Advector advector;
  advector.reserve(velocity.u().count(), 1, Advection::Bfecc);
  for (Advection scheme : {Advection::SemiLagrangian, Advection::MacCormack, Advection::Bfecc}) {
    ScalarGrid out;
    advector.trace(velocity, n, kCellOffset, dt, h, scheme, used);
    advector.advect(phi, out, Interpolation::MonotonicCubic, used, 0.f);
    const ScalarGrid expected = reference(velocity, phi, dt / h, scheme);
    std::size_t zeros = 0;
    for (std::size_t c = 0; c < phi.count(); ++c) {
      ASSERT_EQ(std::memcmp(&out[c], &expected[c], sizeof(float)), 0)
          << int(scheme) << " " << c << ": " << out[c] << " vs " << expected[c];
      zeros += out[c] == 0.f;
    }
    EXPECT_GT(zeros, phi.count() / 2);  // most runs were clean air, so skipped
  }
}

TEST(AdvectionClean, SkippedCleanRunsGiveTheFormulasBitForBit) {
  const glm::ivec3 n(32, 20, 14);  // rows of 32: whole runs of eight
  expectFormulas(n, sparseField(n, 11, true), false);
}

TEST(AdvectionClean, SkippedCleanRunsInAMaskGiveTheFormulasBitForBit) {
  const glm::ivec3 n(64, 48, 40);
  expectFormulas(n, sparseField(n, 12, false), true);
}

}  // namespace
}  // namespace plume
