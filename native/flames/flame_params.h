#pragma once
/// \file flame_params.h
/// The artist's settings of the flame structure ([Structural Flames] §4.1–4.3) and of one flame
/// source (§4.2 moving sources, §6.2 spread maps: activation time, duration, intensity, diameter,
/// height). Units: metres, seconds; Blender Z up.

#include "flames/spine_noise.h"

#include <glm/glm.hpp>

#include <limits>

namespace plume {

/// How eq. 1 is integrated over a step ("explicit Euler ... Runge-Kutta is sufficient", §4.1).
enum class FlameIntegrator { Euler, Midpoint, RungeKutta4 };

/// Bounds of a spine's control points n (§4.1): FlameParams::validate() checks them and the
/// add-on reads them (_native.setting_ranges()["flames.points"]).
constexpr int kMinSpinePoints = 2;
constexpr int kMaxSpinePoints = 256;

/// Structure settings shared by every flame of a system (§4.1–4.3). validate() throws
/// std::invalid_argument naming the setting and the accepted range.
struct FlameParams {
  /// n, control points of an attached flame's spine (§4.1), in [kMinSpinePoints, kMaxSpinePoints].
  int points = 16;
  /// H_p, top of the persistent (continuous) region (m, Figure 2), in [0, H_i).
  double heightPersistent = 0.15;
  /// H_i, top of the intermittent region (m, Figure 2): flames longer than this may break (§4.3).
  double heightIntermittent = 0.3;
  /// H_max, artistic limit on flame length (m): D(h) = 1 past it (§4.3), in [H_i, 1000].
  double heightMax = 0.6;
  /// A, length scale of a separated flame's life A·i³ (s, §4.3), in [1/24, 2].
  double lifespanScale = 0.5;
  /// f, breakaway rate while a flame is longer than H_i (Hz, §4.3), in [0, 1000]; 0 = automatic,
  /// f = 0.50 (|g|/2r)^½ for a source of radius r.
  double breakawayFrequency = 0.0;
  /// Separated flames may break again (§4.3: "no reason why the buoyant flame can't separate").
  bool separatedCanSplit = true;
  /// β of eq. 2, thermal expansion coefficient (1 per unit of normalized temperature), in [0, 100].
  double buoyancy = 0.5;
  /// T_0 of eq. 2, ambient temperature (normalized; a source's T_p is 1 by default), in [-10, 10].
  double ambientTemperature = 0.0;
  /// Diffusion coefficient of the Brownian term d(T_p) of eq. 1 (m²/s), in [0, 10].
  double diffusion = 1e-4;
  /// g, gravity (m/s², Blender Z up); buoyancy acts along -g; |g| in [0.01, 1000].
  glm::dvec3 gravity{0.0, 0.0, -9.81};
  /// Integration of eq. 1 over a step.
  FlameIntegrator integrator = FlameIntegrator::Midpoint;
  /// Control points are kept at least this far outside obstacles (m, §6.1), in [0, 1].
  double obstacleMargin = 1e-3;
  /// v_K of eq. 1: the Kolmogorov velocity on every control point (§4.2, §7 torch).
  SpineNoiseParams spineNoise;

  /// Throws std::invalid_argument for a setting outside its range (message names it).
  void validate() const;
  /// f (Hz) for a source of radius r (m): breakawayFrequency, or 0.50 (|g|/2r)^½ when it is 0.
  /// The text prints "(0.50 − 0.04)": read as 0.50 ± 0.04 (the measured spread), mean 0.50.
  double frequency(double radius) const;
};

/// One burning surface point (§4.1), with its motion (§4.2) and spread-map values (§6.2).
struct FlameSource {
  glm::dvec3 position{0.0};         ///< where particles are released (m)
  glm::dvec3 normal{0.0, 0.0, 1.0}; ///< outward surface normal (direction of a still flame's first segment)
  double radius = 0.02;             ///< r (m): f of §4.3 and the profile's scale, in (0, 100]
  glm::dvec3 velocity{0.0};         ///< V, the surface's motion through the air (m/s, §4.2)
  double startTime = 0.0;           ///< activation time (s, §6.2): burns over [start, end)
  double endTime = std::numeric_limits<double>::infinity();  ///< end of burning (s)
  double intensity = 1.0;           ///< scales I of eq. 4 (§6.2 intensity map), in [0, 1000]
  double diameterScale = 1.0;       ///< scales radius (§6.2 diameter map), in (0, 100]
  double heightScale = 1.0;         ///< scales H_p, H_i, H_max (§6.2 height map), in (0, 100]
  double temperature = 1.0;         ///< T_p of the flames it feeds (normalized), in [0, 100]
  double brightness = 1.0;          ///< 2^(Intensity stops): scales E of its flames, in (0, 2^40]

  /// Throws std::invalid_argument naming "sources[index].<setting>" and its range.
  void validate(int index) const;
  /// Radius with the diameter scale applied (m).
  double scaledRadius() const { return radius * diameterScale; }
  /// Whether it burns at time t: startTime <= t < endTime.
  bool activeAt(double t) const { return t >= startTime && t < endTime; }
};

}  // namespace plume
