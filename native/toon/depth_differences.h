#pragma once
/// \file depth_differences.h
/// The depth-differences outline test of [Cartoon Smoke] §2.2 (after Deussen & Strothotte
/// 2000), as a reference for the compositor node group: pixel (i, j) is drawn in the outline
/// colour when any of its four one-sided depth differences, divided by the pixel size, exceeds γ:
///   |z(i+1,j) - z(i,j)| / Δx > γ  or  |z(i,j) - z(i-1,j)| / Δx > γ  or
///   |z(i,j+1) - z(i,j)| / Δy > γ  or  |z(i,j) - z(i,j-1)| / Δy > γ.
/// A neighbour outside the image is skipped (no difference across the border).

#include <cstdint>
#include <limits>

namespace plume {

/// Settings of the test.
struct DepthDifferenceParams {
  float gamma = 1.f;  ///< γ, the depth threshold (depth units per pixel-size unit), >= 0
  float dx = 1.f;     ///< Δx, pixel width, > 0
  float dy = 1.f;     ///< Δy, pixel height, > 0
  /// Background pixels (depth not < `far`, so also +inf and NaN) are never outline pixels;
  /// smoke pixels beside the background still are (the silhouette is drawn on the smoke side).
  bool ignoreBackground = false;
  float far = std::numeric_limits<float>::infinity();  ///< depth at and beyond which is background
  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
};

/// §2.2 test on a depth image of `height` rows of `width` pixels (row j at depth + j * width,
/// pixel i at column i): out[j * width + i] = 1 for an outline pixel, else 0. Row-parallel and
/// vectorized, each difference computed once; the result equals the per-pixel formula exactly
/// (division by Δ, or multiplication by 1/Δ when Δ is a power of two, which rounds the same).
/// Throws std::invalid_argument for bad params or sizes.
void depthDifferences(const float* depth, int width, int height,
                      const DepthDifferenceParams& params, std::uint8_t* out);

}  // namespace plume
