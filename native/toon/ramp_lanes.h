#pragma once
/// \file ramp_lanes.h
/// The per-particle rules of [Cartoon Smoke] §2.3 on four SSE lanes, for the toon particles'
/// sample stage: the size ramp (0 below ρ_death), the colour ramp and the bounded size step. Each
/// lane gives exactly the scalar forms of ToonParams (rampSize, colorParameter, unitRamp) and of
/// the step in toon_particles.h: the same IEEE operations (division, not a reciprocal) in the
/// same order, with selects in place of branches.

#include <smmintrin.h>

#include <limits>

#include "toon/toon_params.h"

namespace plume {

/// Lanes that are finite numbers (no NaN, no infinity): std::isfinite per lane.
inline __m128 finiteLanes(__m128 v) {
  return _mm_cmple_ps(_mm_andnot_ps(_mm_set1_ps(-0.f), v),
                      _mm_set1_ps(std::numeric_limits<float>::max()));
}

/// c ? a : b per lane (c from a comparison).
inline __m128 selectLanes(__m128 c, __m128 a, __m128 b) { return _mm_blendv_ps(b, a, c); }

/// The ramps of one ToonParams on four lanes.
class RampLanes4 {
 public:
  explicit RampLanes4(const ToonParams& p) : mP(p), mStep(p.maxSizeStep()) {}

  /// ToonParams::unitRamp: (v - lo) / (hi - lo) clamped to [0, 1], NaN giving 0.
  static __m128 unitRamp(__m128 v, float lo, float hi) {
    const __m128 t = _mm_div_ps(_mm_sub_ps(v, _mm_set1_ps(lo)), _mm_set1_ps(hi - lo));
    const __m128 one = _mm_set1_ps(1.f);
    // t > 0 ? (t < 1 ? t : 1) : 0 (the comparisons fail on NaN, as the scalar ones do).
    return _mm_and_ps(_mm_cmpgt_ps(t, _mm_setzero_ps()), selectLanes(_mm_cmplt_ps(t, one), t, one));
  }

  /// The target size: 0 below ρ_death or where the ramp is not finite, else rampSize(density).
  __m128 targetSize(__m128 density) const {
    const __m128 ramp =
        _mm_add_ps(_mm_set1_ps(mP.sizeLow),
                   _mm_mul_ps(_mm_set1_ps(mP.sizeHigh - mP.sizeLow),
                              unitRamp(density, mP.rampDensityLow, mP.rampDensityHigh)));
    const __m128 keep =
        _mm_andnot_ps(_mm_cmplt_ps(density, _mm_set1_ps(mP.deathDensity)), finiteLanes(ramp));
    return _mm_and_ps(keep, ramp);
  }

  /// ToonParams::colorParameter of the lanes; `velocity` = the x, y, z components (their length
  /// is the speed: sqrt((x² + y²) + z²), glm::length's order).
  __m128 color(__m128 density, __m128 temperature, const __m128* velocity) const {
    __m128 v = density;
    if (mP.colorDriver == ToonColorDriver::Temperature) v = temperature;
    if (mP.colorDriver == ToonColorDriver::Speed) {
      const __m128 xx = _mm_mul_ps(velocity[0], velocity[0]),
                   yy = _mm_mul_ps(velocity[1], velocity[1]);
      const __m128 zz = _mm_mul_ps(velocity[2], velocity[2]);
      v = _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(xx, yy), zz));
    }
    return unitRamp(v, mP.colorLow, mP.colorHigh);
  }

  /// §2.3 temporal coherence: size moves toward target by at most maxSizeStep() per frame,
  /// |target - size| <= step ? target : (target > size ? size + step : size - step).
  __m128 sizeStep(__m128 size, __m128 target) const {
    const __m128 step = _mm_set1_ps(mStep), diff = _mm_sub_ps(target, size);
    const __m128 moved = selectLanes(_mm_cmpgt_ps(diff, _mm_setzero_ps()), _mm_add_ps(size, step),
                                     _mm_sub_ps(size, step));
    const __m128 absDiff = _mm_andnot_ps(_mm_set1_ps(-0.f), diff);
    return selectLanes(_mm_cmple_ps(absDiff, step), target, moved);
  }

 private:
  const ToonParams& mP;
  float mStep;
};

}  // namespace plume
