#pragma once
/// \file blackbody.h
/// The colour of a blackbody ([Structural Flames] §5.1: "hotter regions are bluer"), the
/// fallback base colour of a flame particle when no colour image is given: Planck's law
/// integrated against the CIE 1931 2° colour-matching functions (the multi-lobe Gaussian fit of
/// Wyman, Sloan and Shirley 2013) from 380 to 780 nm, converted to linear Rec. 709 (Blender's
/// scene-linear primaries), negative components clipped, scaled to luminance Y = 1: a
/// chromaticity; the particle's brightness comes from eq. 6.

#include <glm/glm.hpp>

#include <vector>

namespace plume {

/// Linear Rec. 709 colour of a blackbody at `kelvin` (clamped to [500, 40000] K), luminance 1.
glm::vec3 blackbodyColor(double kelvin);

/// blackbodyColor(f · kelvin) for f ∈ [0, 1], tabulated once (the spectral integral costs ~1 µs,
/// too much per particle): 256 entries, linear between them (the colour changes smoothly in T).
class BlackbodyRamp {
 public:
  explicit BlackbodyRamp(double kelvin);
  glm::vec3 operator()(double fraction) const;

 private:
  std::vector<glm::vec3> mTable;
};

/// Rec. 709 luminance 0.2126 R + 0.7152 G + 0.0722 B.
inline float luminance(const glm::vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

}  // namespace plume
