#pragma once
/// \file incandescence.h
/// Rendering data of [Structural Flames] §5: base colour from a reference image mapped on the
/// 2-D profile (§5.1), the flame's energy (eq. 5), each particle's incandescence (eq. 6) and
/// the light standing for a flame (§5.2: an emitting sphere of radius h/3 at its centre).

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace plume {

/// A reference image (§5.1): RGB floats, row 0 at the bottom (Blender's pixel order), mapped
/// on the profile's side view: u across the flame's widest diameter (−R … R), v from the base
/// of the profile to its tip; the glow outside the profile takes the nearest edge's colour.
/// Empty: white.
struct ColorImage {
  int width = 0, height = 0;
  std::vector<float> rgb;  ///< width · height · 3
  /// Throws std::invalid_argument when the sizes disagree or a value is not finite.
  void validate() const;
  /// Bilinear colour at (u, v) ∈ [0, 1]² (clamped); white when empty.
  glm::vec3 sample(double u, double v) const;
};

/// Settings of eq. 5.
struct IncandescenceParams {
  double k = 1.0;                    ///< visual scale factor
  double heatOfCombustion = 15.0e6;  ///< H_c, J/kg (15 MJ/kg wood, 48 MJ/kg gasoline)
  double fuelArea = 0.0;             ///< A_f, m²: fuel surface area; 0: the source disc π r²
  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
};

/// Eq. 5: E = ½ k · 0.3 m · H_c · 2 A_f r³ / h with m = |v_c| r² (v_c the mean velocity of the
/// spine's control points), r the radius (m), h the flame length (m).
double flameEnergy(const IncandescenceParams& params, double speed, double radius, double height);

/// Eq. 6 per unit density: E_i = factor · d(x_i) with
///   factor = E / (n · 4π ((h/2)² + l²) · ⟨d⟩).
/// Two readings: the printed eq. 6 lacks E (the particles share the flame's energy, so it must be
/// there) and has 4 where the irradiance of a point source at distance l has 4π (π lost in
/// extraction); ⟨d⟩ is the automatic adjustment of k "for the energy loss due to the d(x_i)
/// term": the expected d of a sample, so Σ E_i → E / (4π ((h/2)² + l²)) for any n.
double incandescenceFactor(double energy, std::size_t count, double meanDensity, double height, double distance);

/// The light of one flame (a flame or a separated piece: §5.2's "flame segment").
struct FlameLight {
  std::uint32_t flameId = 0;
  glm::dvec3 centre{0.0};  ///< the spine point at half the arc length
  double radius = 0.0;     ///< h/3
  double energy = 0.0;     ///< eq. 5 times the flame's intensity
  glm::vec3 color{1.f};    ///< power-weighted mean base colour of its particles, luminance 1
};

}  // namespace plume
