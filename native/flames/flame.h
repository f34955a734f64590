#pragma once
/// \file flame.h
/// The data every stage of the structural-flames pipeline ([Structural Flames]) shares: one
/// flame is its spine, the n points an interpolating B-spline passes through (§4.1), from the
/// base on the burning surface (index 0) to the tip (index n-1), with what each point carries
/// for eq. 1 and the later stages. Structure (spine, evolution, breakaway: §4.1–4.3) produces
/// flames; shape (profiles, sampling, noise, mapping, merging: §4.4–4.5) and rendering (§5)
/// read them.

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace plume {

/// One structural point p of a spine (eq. 1).
struct SpinePoint {
  glm::dvec3 x{0.0};  ///< x_p, world position (m)
  glm::dvec3 v{0.0};  ///< dx_p/dt of the last step (m/s): flow-noise propagation, motion blur, smoke
  double age = 0.0;   ///< t_p, time since the point left the burning surface (s), eq. 2
};

/// One flame: a spine attached to its source, or a separated (broken-off) piece (§4.3).
struct Flame {
  std::uint32_t id = 0;   ///< unique within a bake, stable over frames (lights, curves)
  int source = 0;         ///< index of the flame source (or of the source point) it came from
  bool separated = false; ///< broken off the top of a flame (§4.3): no base, limited life
  double age = 0.0;       ///< s since the flame (or the piece) appeared
  double lifespan = 0.0;  ///< separated pieces: A·i³ (s); attached flames: 0 (burn while active)
  double radius = 0.0;    ///< r, the source radius (m): the profile's scale and f's r (§4.3)
  double intensity = 1.0; ///< I of eq. 4 times the artist's intensity (spread maps, §6.2)
  double temperature = 1.0;  ///< T_p, normalized flame temperature (diffusion, buoyancy: eq. 1–2)
  /// The artist's brightness, 2^(Intensity in stops) of its source: k of eq. 5 ("for visual
  /// control") per source, on top of the one physical Light Unit. Scales E (emission and light)
  /// only, never the opacity.
  double brightness = 1.0;
  /// Separated pieces: h of the flame they broke from, at the split (0: attached, or unknown).
  /// Eq. 5's 1/h would make a short piece brighter than its whole parent; a piece carries the
  /// parent's fuel over its share of the length instead: E = E(h_split) · h / h_split.
  double splitLength = 0.0;
  std::vector<SpinePoint> points;  ///< base (0) to tip (n-1); at least 2
};

}  // namespace plume
