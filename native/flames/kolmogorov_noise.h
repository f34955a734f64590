#pragma once
/// \file kolmogorov_noise.h
/// Turbulent detail of [Structural Flames] §4.5: a world-space vector field with a Kolmogorov
/// energy spectrum E(k) ∝ k^(−5/3) (Stam & Fiume 1993), displacing every flame's samples after
/// the spine mapping. One field for all flames, so neighbouring (merging) flames move alike.
///
/// The field is a periodic tile of N³ vectors synthesized once by an inverse FFT of random
/// Gaussian Fourier coefficients with amplitude |k|^(−11/6) (so the shell energy
/// 4πk² |a(k)|² ∝ k^(−5/3)) for 1 ≤ |k| ≤ N/2, projected to be divergence-free (incompressible
/// turbulence; the projection removes a third of the energy at every k, so the slope is kept),
/// scaled to unit RMS magnitude and read trilinearly. It is animated per frame ("generated on a
/// per-frame basis") as frozen turbulence carried by a drift velocity, blended with a second,
/// decorrelated part of the tile: F(x, t) = cos φ T(x − c t) + sin φ T(x − c t + Λ/2),
/// φ = 2π ν t, which keeps the variance (cos² + sin² = 1) and changes smoothly with t.

#include <glm/glm.hpp>

#include <complex>
#include <cstdint>
#include <vector>

namespace plume {

/// Bounds of KolmogorovParams: validate() checks them and the add-on reads them
/// (_native.setting_ranges()["flames.kolmogorov*"]).
constexpr double kMaxKolmogorovAmplitude = 100.0;   ///< m
constexpr double kMaxKolmogorovScale = 1.0e4;       ///< m, Λ in (0, this]
constexpr double kMaxKolmogorovFrequency = 1000.0;  ///< Hz
constexpr double kMaxKolmogorovDrift = 1000.0;      ///< m/s, each component of c in [−this, this]

/// Settings of the Kolmogorov noise.
struct KolmogorovParams {
  double amplitude = 0.01;  ///< RMS displacement, m (0 turns it off)
  double scale = 0.5;       ///< Λ, the tile period: the largest eddy, m
  glm::dvec3 drift{0.0, 0.0, 0.5};  ///< c, m/s: how the frozen field is carried
  double frequency = 0.5;   ///< ν, Hz: how fast the field changes in place
  int resolution = 32;      ///< N, a power of two in [8, 128]
  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
};

/// The periodic Kolmogorov vector field of one seed.
class KolmogorovNoise {
 public:
  KolmogorovNoise(const KolmogorovParams& params, std::uint64_t seed);
  /// The unit-RMS tile at tile coordinates u (one period = N), trilinear, periodic.
  glm::dvec3 tile(const glm::dvec3& u) const;
  /// The displacement (m) at world x and time t (s).
  glm::dvec3 displacement(const glm::dvec3& x, double t) const;
  /// The same for many points at one t: the blend weights (cos φ, sin φ) computed once.
  glm::dvec3 displacement(const glm::dvec3& x, double t, glm::dvec2 blend) const;
  /// (cos φ, sin φ), φ = 2π ν t.
  glm::dvec2 blend(double t) const;
  const KolmogorovParams& params() const { return mParams; }

 private:
  friend class KolmogorovFrame;
  KolmogorovParams mParams;
  int mN = 0;
  std::vector<glm::vec3> mTile;  ///< x fastest
};

/// The field at one time t (§4.5, "generated on a per-frame basis"): the two parts of the tile
/// blended once per frame, B = cos φ T(i) + sin φ T(i + N/2), so a lookup reads 8 corners
/// instead of 16. The same single-precision products and sums as KolmogorovNoise::displacement,
/// so the values are the same bit for bit.
class KolmogorovFrame {
 public:
  KolmogorovFrame(const KolmogorovNoise& noise, double t);
  /// KolmogorovNoise::displacement(x, t).
  glm::dvec3 displacement(const glm::dvec3& x) const;

 private:
  const KolmogorovNoise& mNoise;
  double mTime;
  std::vector<glm::vec3> mBlend;  ///< x fastest, N³
};

/// In-place 3-D FFT of an N³ complex array (x fastest), N a power of two; inverse without the
/// 1/N³ factor. Exposed for the spectrum tests.
void fft3d(std::vector<std::complex<double>>& data, int n, bool inverse);

}  // namespace plume
