#pragma once
/// \file toon_params.h
/// Settings of the cartoon-smoke particles ([Cartoon Smoke] §2.1 and §2.3): emission at the
/// source, birth and death thresholds on density, the size and colour ramps, the largest size
/// change per frame (temporal coherence), the particle budget, integration and squash/stretch.

#include <cstdint>
#include <string>

namespace plume {

/// How particles are advected through one frame (§2.1: "advected ... using Euler integration").
enum class ToonIntegration {
  Euler,     ///< x += h u(x, t) per substep, as the paper
  Midpoint,  ///< explicit midpoint rule per substep (second order in time)
};

/// The particle quantity that drives the colour ramp (§2.3, Figure 1 right, Figure 6).
enum class ToonColorDriver { Density, Temperature, Speed };

/// Limits of the accepted settings (validate() names them in its messages).
constexpr int kMaxToonParticles = 50000000;
constexpr int kMaxToonEmission = 1000000;
constexpr float kMinToonCfl = 0.05f;
constexpr float kMaxToonCfl = 10.f;
constexpr int kMaxToonSubsteps = 4096;
constexpr float kMaxToonBirthSpacing = 10.f;

/// Every setting of the toon particles. Densities are in the field's units, sizes in metres
/// (stencil diameter in world space), speeds in m/s.
struct ToonParams {
  /// Particles emitted per frame at the source (§2.1 "introducing massless marker particles
  /// periodically at the smoke source"), spread in turn over the source cells and points.
  int emissionCount = 10;
  /// ρ_birth: a cell denser than this that holds no particle gets a new one (§2.2 last paragraph).
  float birthDensity = 0.5f;
  /// σ: a newborn is kept only when no particle lies closer than σ s(ρ) to it, s(ρ) the size
  /// ramp at its cell's density (birth_spacing.h), so newborns stay apart like puffs instead of
  /// filling every dense cell; 0 = the paper's rule (every empty dense cell), in stencil sizes.
  float birthSpacing = 0.5f;
  /// ρ_death: a particle in thinner smoke shrinks to size 0, then is removed (§2.3).
  float deathDensity = 0.05f;
  /// Size ramp (§2.3 "the higher the density the larger the particle"): density d0..d1 maps
  /// linearly onto size s0..s1, clamped outside. The defaults are 2 to 5 cells of a 2 m domain
  /// at 40 cells: stencils smaller than a cell are a cloud of specks whose front is rough in
  /// depth, which the depth differences (§2.2) outline as speckles all over the smoke.
  float rampDensityLow = 0.f;
  float rampDensityHigh = 1.f;
  float sizeLow = 0.1f;
  float sizeHigh = 0.25f;
  /// Largest size change per frame as a fraction of the ramp's largest size max(s0, s1): a full
  /// size particle needs at least 1 / fraction frames to vanish, so it never pops (§2.3). The
  /// default grows a newborn in 4 frames: growing ones are small specks in front of the smoke.
  float maxSizeChange = 0.25f;
  /// Particle budget: birth and emission stop (in their deterministic order) when it is reached.
  int maxCount = 200000;
  ToonIntegration integration = ToonIntegration::Euler;
  /// Most cells a particle may cross per substep (the frame is cut into equal substeps).
  float cfl = 1.f;
  /// Seed of every random birth and emission position.
  std::uint64_t seed = 0;
  /// k in stretch = 1 + k |v_screen| (Figure 4: stretch ∝ speed), seconds per metre.
  float stretchFactor = 0.5f;
  /// Colour ramp input: the driver's value c0..c1 maps linearly onto 0..1, clamped.
  ToonColorDriver colorDriver = ToonColorDriver::Density;
  float colorLow = 0.f;
  float colorHigh = 1.f;
  /// Worker threads; 0 = all cores. Results do not depend on it.
  int threads = 0;

  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;

  /// §2.3 size ramp: s0 + (s1 - s0) clamp((d - d0) / (d1 - d0), 0, 1).
  float rampSize(float density) const {
    return sizeLow + (sizeHigh - sizeLow) * unitRamp(density, rampDensityLow, rampDensityHigh);
  }
  /// §2.3 colour ramp parameter in [0, 1] from a particle's density, temperature and speed.
  float colorParameter(float density, float temperature, float speed) const {
    const float v = colorDriver == ToonColorDriver::Density
                        ? density
                        : (colorDriver == ToonColorDriver::Temperature ? temperature : speed);
    return unitRamp(v, colorLow, colorHigh);
  }
  /// (v - lo) / (hi - lo) clamped to [0, 1] (NaN gives 0).
  static float unitRamp(float v, float lo, float hi) {
    const float t = (v - lo) / (hi - lo);
    return t > 0.f ? (t < 1.f ? t : 1.f) : 0.f;
  }
  /// Largest size change per frame in metres: maxSizeChange * max(s0, s1).
  float maxSizeStep() const;
};

}  // namespace plume
