#include "solver/advection.h"

#include "solver/inflow.h"
#include "solver/linear_runs.h"

#include <algorithm>
#include <stdexcept>

namespace plume {
namespace {

constexpr int kRun = BlockMask::kBlock;  ///< longest x-run forEachRun() hands out
static_assert(kRun == kLinearRun, "the fused kernels take whole runs");

/// Samples of `src` at the traced points first .. first+count-1 (count <= kRun).
inline void sampleRun(const ScalarGrid& src, const SamplePoints& traced, std::size_t first,
                      int count, Interpolation interpolation, float* out) {
  if (interpolation == Interpolation::Linear) sampleLinear(src, traced, first, count, out);
  else sampleMonotonicCubic(src, traced, first, count, out);
}

/// True when points first .. first+count-1 all fall in cells of `clean` with an all-background
/// stencil.
inline bool allClean(const CleanStencils& clean, const SamplePoints& traced, std::size_t first,
                     int count) {
  const std::uint32_t* index = traced.index() + first;
  const std::uint8_t* dirty = clean.dirty();
  std::uint8_t any = 0;
  for (int m = 0; m < count; ++m) any |= dirty[index[m] & SamplePoints::kIndexMask];
  return any == 0;
}

/// One semi-Lagrangian pass of `count` fields: dst[f](x) = src[f](trace(x)), then
/// finish(f, c, n, values) applies the corrections and limiters of BFECC and MacCormack in
/// place to the n values of a run starting at linear index c. The fields of a run are done one
/// after the other while its split points are in L1. Full runs of trilinear samples go to
/// fused(f, c, out), the same pass in one AVX2 kernel (linear_runs.h), where the CPU has it.
///
/// With `clean` (one CleanStencils of each src, built for this pass), a run whose points all
/// fall in cells with an all-background stencil takes the background value without sampling:
/// the value sampling gives there, bit for bit.
template <typename Finish, typename Fused>
void pass(const ScalarGrid* const* src, ScalarGrid* const* dst, const float* background,
          std::size_t count, const SamplePoints& traced, Interpolation interpolation,
          const BlockMask* mask, const CleanStencils* clean, const Finish& finish,
          const Fused& fused) {
  const ScalarGrid& first = *src[0];
  const bool useFused = interpolation == Interpolation::Linear && linearRunsAvailable();
  forEachRun(
      first.size(), mask,
      [&](int i0, int i1, int j, int k) {
        const std::size_t c = first.index(i0, j, k);
        const int n = i1 - i0;
        for (std::size_t f = 0; f < count; ++f) {
          if (useFused && n == kLinearRun) {
            fused(f, c, dst[f]->data() + c);
            continue;
          }
          float values[kRun];
          if (clean && allClean(clean[f], traced, c, n)) std::fill(values, values + n, background[f]);
          else sampleRun(*src[f], traced, c, n, interpolation, values);
          finish(f, c, n, values);
          std::copy(values, values + n, dst[f]->data() + c);
        }
      },
      [&](int i0, int i1, int j, int k) {
        const std::size_t c = first.index(i0, j, k);
        for (std::size_t f = 0; f < count; ++f)
          std::fill(dst[f]->data() + c, dst[f]->data() + c + std::size_t(i1 - i0), background[f]);
      });
}

/// The plain semi-Lagrangian value.
constexpr auto kAsIs = [](std::size_t, std::size_t, int, float*) {};

/// values[0 .. n-1] clamped to the range of φ around the back-traced points c .. c+n-1 (the
/// limiter of BFECC and MacCormack: no new extrema).
inline void clampToRange(const ScalarGrid& phi, const SamplePoints& back, std::size_t c, int n,
                         float* values) {
  float lo[kRun], hi[kRun];
  sampleRange(phi, back, c, n, lo, hi);
  for (int m = 0; m < n; ++m)
    values[m] = values[m] < lo[m] ? lo[m] : (values[m] > hi[m] ? hi[m] : values[m]);
}

}  // namespace

void Advector::reserve(std::size_t count, std::size_t fields, Advection scheme) {
  fields = std::min(fields, kMaxFields);
  for (std::size_t f = 0; f < fields; ++f) {
    // φ̂ for BFECC and MacCormack, φ + ½(φ - φ̄) for BFECC only.
    if (scheme != Advection::SemiLagrangian) mForward[f].reserve(count);
    if (scheme == Advection::Bfecc) mBackward[f].reserve(count);
  }
  mBack.reserve(count);
  mFore.reserve(count);
}

void Advector::trace(const MacGrid3& velocity, glm::ivec3 size, glm::vec3 offset, float dt,
                     float cellSize, Advection scheme, const BlockMask* mask, Trace order,
                     std::uint8_t openSides) {
  mScheme = scheme;
  // Only the back-traces read the air beyond the open sides: the forward traces of BFECC and
  // MacCormack serve their error estimate, which the fall-back below discards there.
  mBack.setGhostSides(openSides);
  // Traces are made once and stored for every pass (32 bytes a sample): made again in each pass
  // that reads them, even Euler traces cost 1.4 times as much (measured at 128³).
  // BFECC and MacCormack also need the forward traces (their reverse step A⁻¹).
  const bool both = scheme != Advection::SemiLagrangian;
  mTracer.trace(velocity, size, offset, dt / cellSize, order, mask, mBack, both ? &mFore : nullptr);
}

void Advector::advect(const ScalarGrid& src, ScalarGrid& dst, Interpolation interpolation,
                      const BlockMask* mask, float background, const ScalarGrid* ambient) {
  const Field field{&src, &dst, background, ambient};
  advect(&field, 1, interpolation, mask);
}

void Advector::advect(const Field* fields, std::size_t count, Interpolation interpolation,
                      const BlockMask* mask) {
  if (count == 0) return;
  if (count > kMaxFields) throw std::logic_error("Advector::advect: more than kMaxFields fields");
  const glm::ivec3 size = fields[0].src->size();
  const glm::ivec3 traced = mBack.gridSize();
  const ScalarGrid* src[kMaxFields];
  ScalarGrid *dst[kMaxFields], *forward[kMaxFields], *backward[kMaxFields];
  float background[kMaxFields];
  for (std::size_t f = 0; f < count; ++f) {
    if (fields[f].src->size() != size || size != traced)
      throw std::logic_error("Advector::advect: a field differs from the traced grid");
    src[f] = fields[f].src;
    dst[f] = fields[f].dst;
    dst[f]->reshape(size);
    background[f] = fields[f].background;
    forward[f] = &mForward[f];
    backward[f] = &mBackward[f];
  }
  // Samples whose back-trace ended past an open side take in the air outside (inflow.h).
  const ScalarGrid* ambient[kMaxFields];
  for (std::size_t f = 0; f < count; ++f) ambient[f] = fields[f].ambient;
  auto inflow = [&](ScalarGrid* const* grids) {
    blendInflow(grids, count, background, ambient, mBack, mask);
  };
  // Cubic passes skip the runs whose stencils hold clean air only (most of a plume's domain, in
  // the active blocks or without a mask); trilinear runs cost about what the test would.
  const bool skipClean = interpolation == Interpolation::MonotonicCubic;
  auto cleanOf = [&](const ScalarGrid* const* grids) -> const CleanStencils* {
    if (!skipClean) return nullptr;
    for (std::size_t f = 0; f < count; ++f) mClean[f].build(*grids[f], background[f], mask);
    return mClean;
  };
  if (mScheme == Advection::SemiLagrangian) {
    pass(src, dst, background, count, mBack, interpolation, mask, cleanOf(src), kAsIs,
         [&](std::size_t f, std::size_t c, float* out) { semiLagrangianRun(*src[f], mBack, c, out); });
    inflow(dst);
    return;
  }
  // φ̂ = A(φ): the semi-Lagrangian step along the back-traces.
  for (std::size_t f = 0; f < count; ++f) mForward[f].reshape(size);
  pass(src, forward, background, count, mBack, interpolation, mask, cleanOf(src), kAsIs,
       [&](std::size_t f, std::size_t c, float* out) { semiLagrangianRun(*src[f], mBack, c, out); });
  inflow(forward);
  // Where the air came in from outside, the result is φ̂ itself.
  auto fallBack = [&] { copyInflow(forward, dst, count, mBack, mask); };
  if (mScheme == Advection::MacCormack) {
    // Selle et al. 2008 eq. 7: φ = φ̂ + ½(φⁿ - φ̄) with φ̄ = A⁻¹(φ̂), fused with the reverse step,
    // then clamped to the range of φⁿ around the back-traced point (§4, first limiter).
    pass(
        forward, dst, background, count, mFore, interpolation, mask, cleanOf(forward),
        [&](std::size_t f, std::size_t c, int n, float* bar) {
          const ScalarGrid &phi = *src[f], &hat = *forward[f];
          for (int m = 0; m < n; ++m) bar[m] = hat[c + m] + 0.5f * (phi[c + m] - bar[m]);
          clampToRange(phi, mBack, c, n, bar);
        },
        [&](std::size_t f, std::size_t c, float* out) {
          macCormackRun(*src[f], *forward[f], mBack, mFore, c, out);
        });
    fallBack();
    return;
  }
  // BFECC (Kim et al. 2005): φ̄ = A⁻¹(φ̂) and the corrected field φ + ½(φ - φ̄) in one pass...
  for (std::size_t f = 0; f < count; ++f) mBackward[f].reshape(size);
  pass(
      forward, backward, background, count, mFore, interpolation, mask, cleanOf(forward),
      [&](std::size_t f, std::size_t c, int n, float* bar) {
        const ScalarGrid& phi = *src[f];
        for (int m = 0; m < n; ++m) bar[m] = phi[c + m] + 0.5f * (phi[c + m] - bar[m]);
      },
      [&](std::size_t f, std::size_t c, float* out) {
        bfeccCorrectionRun(*src[f], *forward[f], mFore, c, out);
      });
  // ...then forward again from it, clamped to the range of the original φ (no new extrema).
  pass(
      backward, dst, background, count, mBack, interpolation, mask, cleanOf(backward),
      [&](std::size_t f, std::size_t c, int n, float* values) {
        clampToRange(*src[f], mBack, c, n, values);
      },
      [&](std::size_t f, std::size_t c, float* out) {
        clampedRun(*backward[f], *src[f], mBack, c, out);
      });
  fallBack();
}

}  // namespace plume
