#pragma once
/// \file flow_noise.h
/// Buoyancy noise of [Structural Flames] §4.5: Flow Noise (Perlin & Neyret 2001) — gradient
/// noise whose lattice gradients rotate over time — displacing the samples in canonical profile
/// space, propagating up the profile with the spine's structural points.
///
/// Propagation: the fluctuation a particle at s shows left the base when the spine point now at
/// s did, at τ = t − t_p(s) (t_p the points' age, eq. 2, interpolated along the spine), so the
/// pattern rises at the velocities of the nearest structural particles and nothing has to be
/// stored between frames. The noise is read at q = (x / λ, y / λ, ν τ) with the gradients
/// rotated about the axis by ±ω τ (the sign per lattice point, so neighbouring vortices turn
/// both ways).
///
/// Rotation rate: the paper says the rate "is inversely proportional to the diameter of the flame
/// source, i.e., large flames lead to quicker vector rotation" — the two halves contradict each
/// other. We follow the first: ω = rotation / (2 r), faster for small sources, as the flicker
/// frequency f ∝ (g / 2r)^½ of §4.3 (candles flicker faster than pool fires).

#include <glm/glm.hpp>

#include <cstdint>

namespace plume {

/// Upper bounds of FlowNoiseParams (lower: 0, the scale excluded): validate() checks them and the
/// add-on reads them (_native.setting_ranges()["flames.flow_noise*"]).
constexpr double kMaxFlowNoiseAmplitude = 10.0;    ///< widest radii
constexpr double kMaxFlowNoiseScale = 100.0;       ///< widest radii
constexpr double kMaxFlowNoiseFrequency = 1000.0;  ///< Hz
constexpr double kMaxFlowNoiseRotation = 1000.0;   ///< rad·m/s

/// Settings of the buoyancy (flow) noise.
struct FlowNoiseParams {
  double amplitude = 0.15;  ///< displacement, widest radii (0 turns it off)
  double scale = 0.8;       ///< λ, the noise's feature size across the flame, widest radii
  double frequency = 3.0;   ///< ν, Hz: noise cells leaving the base per second
  double rotation = 0.5;    ///< ω · diameter, rad·m/s: ω = rotation / (2 r)
  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
};

/// Perlin–Neyret flow noise for one seed.
class FlowNoise {
 public:
  FlowNoise(const FlowNoiseParams& params, std::uint64_t seed);
  /// ω for a source of radius r (m): rotation / (2r).
  double rotationRate(double sourceRadius) const;
  /// The rotating gradient noise, each component in about [-1, 1], at q, gradients turned by ±φ.
  glm::dvec3 noise(const glm::dvec3& q, double phi) const;
  /// The displacement (canonical units) of a sample at canonical p whose spine point left the
  /// base at τ (s), on a source of radius r (m).
  glm::dvec3 displacement(const glm::dvec3& p, double tau, double sourceRadius) const;
  const FlowNoiseParams& params() const { return mParams; }

 private:
  FlowNoiseParams mParams;
  std::uint64_t mSeed;
};

}  // namespace plume
