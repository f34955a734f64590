#pragma once
/// \file spine_noise.h
/// The Kolmogorov velocity of eq. 1 ([Structural Flames] §4.2: "we add rotational components in
/// the form of simulated wind fields and a noise field generated from a Kolmogorov spectrum";
/// §7, the torch: "the control points are influenced by thermal buoyancy and Kolmogorov noise").
/// A term v_K(x, t) added to the velocity of every structural particle, next to w, d, V_p and c.
///
/// The field is the Kolmogorov tile of §4.5 (kolmogorov_noise.h: E(k) ∝ k^(−5/3), divergence-free,
/// unit RMS, frozen turbulence carried by the drift c and renewed at ν), read as a velocity: its
/// own seed (the system's, decorrelated from the render particles' field), its own settings.

#include "flames/kolmogorov_noise.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <memory>

namespace plume {

/// Bounds of SpineNoiseParams: validate() checks them and the add-on reads them
/// (_native.setting_ranges()["flames.spine_noise_*"]).
constexpr double kMaxSpineNoiseAmplitude = 100.0;   ///< m/s
constexpr double kMaxSpineNoiseScale = 1.0e4;       ///< m, Λ in (0, this]
constexpr double kMaxSpineNoiseFrequency = 1000.0;  ///< Hz
constexpr double kMaxSpineNoiseDrift = 1000.0;      ///< m/s, each component of c in [−this, this]

/// Settings of the Kolmogorov velocity on the spine's control points (§4.2, §7).
struct SpineNoiseParams {
  /// RMS speed of v_K (m/s), in [0, kMaxSpineNoiseAmplitude]; 0 turns it off. The default, 4 cm/s,
  /// is a tenth of the buoyant rise of a torch flame's points (β |g| t_p ≈ 0.5 m/s after 0.1 s):
  /// over the ~0.2 s a point lives below H_i it drifts sideways ~1 cm, half the radius of a 2 cm
  /// torch source — a visible sway that leaves the flame upright.
  double amplitude = 0.04;
  /// Λ, the period of the tile: the largest eddy (m), in (0, kMaxSpineNoiseScale]. 0.25 m: about
  /// a torch flame's length, so the whole flame sways and its upper part curls.
  double scale = 0.25;
  /// ν (Hz): how fast the field renews in place, in [0, kMaxSpineNoiseFrequency].
  double frequency = 1.0;
  /// c (m/s): the drift carrying the frozen field (up with the hot gas), components in
  /// [−kMaxSpineNoiseDrift, kMaxSpineNoiseDrift].
  glm::dvec3 drift{0.0, 0.0, 0.5};
  /// N, the tile's resolution (a power of two in [8, 128]).
  int resolution = 32;
  /// Throws std::invalid_argument naming the setting ("spine_noise_*") and its accepted range.
  void validate() const;
  bool operator==(const SpineNoiseParams& o) const {
    return amplitude == o.amplitude && scale == o.scale && frequency == o.frequency && drift == o.drift &&
           resolution == o.resolution;
  }
  bool operator!=(const SpineNoiseParams& o) const { return !(*this == o); }
};

/// v_K of one seed: amplitude × the unit-RMS Kolmogorov field.
class SpineNoise {
 public:
  /// Throws std::invalid_argument for bad params.
  SpineNoise(const SpineNoiseParams& params, std::uint64_t seed);
  /// The same for new params, sharing `previous`'s field (of the same seed) when only the
  /// amplitude differs: a keyed amplitude does not synthesize the tile again every frame.
  SpineNoise(const SpineNoiseParams& params, std::uint64_t seed, const SpineNoise& previous);
  /// v_K(x, t) (m/s) at world x (m) and time t (s); zero when the amplitude is 0.
  glm::dvec3 velocity(const glm::dvec3& x, double t) const;
  const SpineNoiseParams& params() const { return mParams; }
  bool enabled() const { return mParams.amplitude > 0.0; }

 private:
  SpineNoiseParams mParams;
  std::shared_ptr<const KolmogorovNoise> mField;  ///< unit amplitude; null when off
};

}  // namespace plume
