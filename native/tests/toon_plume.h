#pragma once
/// \file toon_plume.h
/// A steady synthetic plume for the toon tests and benchmark: a Gaussian column of smoke rising
/// at 1 m/s and turning about the z axis, with its source at the bottom centre.

#include "toon/toon_fields.h"
#include "toon/toon_params.h"

#include <cmath>

namespace plume::testing {

/// The grid of the plume: n cells per axis (z twice as tall), cell size `cell`, origin 0.
inline GridFrame plumeGrid(int n, float cell) {
  return GridFrame{glm::ivec3(n, n, 2 * n), cell, glm::vec3(0.f), 1.f / 24.f};
}

/// Density exp(-r² / 2σ²) (1 - 0.6 z / height) with σ = 0.2 of the width, scaled by `scale`;
/// temperature 2 × density; velocity (-ω y', ω x', 1) m/s about the column's axis (ω = `swirl`).
inline ToonFields plumeFields(const GridFrame& g, float scale = 1.f, float swirl = 0.3f) {
  const glm::ivec3 n = g.resolution;
  const float h = g.cellSize;
  const glm::vec2 axis = 0.5f * glm::vec2(n.x, n.y) * h;
  const float sigma = 0.2f * float(n.x) * h, height = float(n.z) * h;
  ToonFields f;
  f.density.resize(n);
  f.temperature.resize(n);
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const glm::vec3 x = g.origin + (glm::vec3(i, j, k) + 0.5f) * h;
        const glm::vec2 r = glm::vec2(x) - axis;
        const float d = scale * std::exp(-glm::dot(r, r) / (2.f * sigma * sigma)) *
                        (1.f - 0.6f * x.z / height);
        f.density(i, j, k) = d;
        f.temperature(i, j, k) = 2.f * d;
      }
  f.velocity.resize(n);
  // u on x-faces at (i h, (j+½) h), v on y-faces at ((i+½) h, j h).
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i <= n.x; ++i) f.velocity.u()(i, j, k) = -swirl * ((float(j) + 0.5f) * h - axis.y);
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j <= n.y; ++j)
      for (int i = 0; i < n.x; ++i) f.velocity.v()(i, j, k) = swirl * ((float(i) + 0.5f) * h - axis.x);
  f.velocity.w().fill(1.f);
  return f;
}

/// Toon settings for the plume: birth above density 0.5 in every empty cell (the paper's rule,
/// birth spacing 0; toon_birth_test covers the spacing), death below 0.1, sizes 1 to 5 cm over
/// densities 0.1 to 1, at most 10% of the largest size per frame, 8 particles emitted per frame.
inline ToonParams plumeParams() {
  ToonParams p;
  p.birthDensity = 0.5f;
  p.birthSpacing = 0.f;
  p.deathDensity = 0.1f;
  p.rampDensityLow = 0.1f;
  p.rampDensityHigh = 1.f;
  p.sizeLow = 0.01f;
  p.sizeHigh = 0.05f;
  p.maxSizeChange = 0.1f;
  p.emissionCount = 8;
  p.seed = 7;
  return p;
}

/// The 2x2 cells at the bottom centre of the plume.
inline ToonSources plumeSources(const GridFrame& g) {
  const int c = g.resolution.x / 2;
  ToonSources s;
  for (int j = c - 1; j <= c; ++j)
    for (int i = c - 1; i <= c; ++i) s.cells.emplace_back(i, j, 0);
  return s;
}

}  // namespace plume::testing
