#include "solver/linear_runs.h"

#include "core/linear_cells.h"

#include <stdexcept>

namespace plume {

#if defined(PLUME_LINEAR_CELLS_AVX2)

namespace {

/// Trilinear values of `g` at points c .. c+7.
__attribute__((target("avx2"))) inline __m256 sample8(const ScalarGrid& g, const SamplePoints& p,
                                                      std::size_t c) {
  return lerpCells8(cornersOf8(g.data(), Neighbours(g), p.index() + c), p.tx() + c, p.ty() + c,
                    p.tz() + c);
}

/// value clamped to the range of φ around points c .. c+7.
__attribute__((target("avx2"))) inline __m256 clampToRange8(const ScalarGrid& phi,
                                                            const SamplePoints& back,
                                                            std::size_t c, __m256 value) {
  __m256 lo, hi;
  rangeCells8(cornersOf8(phi.data(), Neighbours(phi), back.index() + c), lo, hi);
  return clamp8(value, lo, hi);
}

}  // namespace

bool linearRunsAvailable() { return hasAvx2(); }

__attribute__((target("avx2"))) void semiLagrangianRun(const ScalarGrid& src,
                                                       const SamplePoints& back, std::size_t c,
                                                       float* out) {
  _mm256_storeu_ps(out, sample8(src, back, c));
}

__attribute__((target("avx2"))) void macCormackRun(const ScalarGrid& phi, const ScalarGrid& hat,
                                                   const SamplePoints& back,
                                                   const SamplePoints& fore, std::size_t c,
                                                   float* out) {
  const __m256 bar = sample8(hat, fore, c);
  const __m256 value = _mm256_add_ps(
      _mm256_loadu_ps(hat.data() + c),
      _mm256_mul_ps(_mm256_set1_ps(0.5f), _mm256_sub_ps(_mm256_loadu_ps(phi.data() + c), bar)));
  _mm256_storeu_ps(out, clampToRange8(phi, back, c, value));
}

__attribute__((target("avx2"))) void bfeccCorrectionRun(const ScalarGrid& phi,
                                                        const ScalarGrid& hat,
                                                        const SamplePoints& fore, std::size_t c,
                                                        float* out) {
  const __m256 bar = sample8(hat, fore, c), now = _mm256_loadu_ps(phi.data() + c);
  _mm256_storeu_ps(out, _mm256_add_ps(now, _mm256_mul_ps(_mm256_set1_ps(0.5f), _mm256_sub_ps(now, bar))));
}

__attribute__((target("avx2"))) void clampedRun(const ScalarGrid& src, const ScalarGrid& phi,
                                                const SamplePoints& back, std::size_t c,
                                                float* out) {
  _mm256_storeu_ps(out, clampToRange8(phi, back, c, sample8(src, back, c)));
}

#else

// Without AVX2 the generic passes run; these are never called.
bool linearRunsAvailable() { return false; }
void semiLagrangianRun(const ScalarGrid&, const SamplePoints&, std::size_t, float*) {
  throw std::logic_error("semiLagrangianRun: no AVX2 build");
}
void macCormackRun(const ScalarGrid&, const ScalarGrid&, const SamplePoints&, const SamplePoints&,
                   std::size_t, float*) {
  throw std::logic_error("macCormackRun: no AVX2 build");
}
void bfeccCorrectionRun(const ScalarGrid&, const ScalarGrid&, const SamplePoints&, std::size_t,
                        float*) {
  throw std::logic_error("bfeccCorrectionRun: no AVX2 build");
}
void clampedRun(const ScalarGrid&, const ScalarGrid&, const SamplePoints&, std::size_t, float*) {
  throw std::logic_error("clampedRun: no AVX2 build");
}

#endif

}  // namespace plume
