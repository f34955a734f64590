#pragma once
/// \file test_meshes.h
/// Meshes shared by the unit tests and the benchmarks (header only; not part of plume_core).

#include "solver/emitters.h"

#include <cmath>
#include <string>

namespace plume {

/// UV sphere of radius r around c (closed, manifold: poles are single vertices).
inline EmitterMesh sphereMesh(glm::vec3 c, float r, int rings, int segments,
                              const std::string& name = "sphere") {
  EmitterMesh m;
  m.name = name;
  m.vertices.push_back(c + glm::vec3(0, 0, r));
  for (int a = 1; a < rings; ++a) {
    const double th = M_PI * a / rings;
    for (int b = 0; b < segments; ++b) {
      const double ph = 2 * M_PI * b / segments;
      m.vertices.push_back(c + r * glm::vec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph),
                                             std::cos(th)));
    }
  }
  m.vertices.push_back(c - glm::vec3(0, 0, r));
  const int south = int(m.vertices.size()) - 1;
  auto ring = [&](int a, int b) { return 1 + (a - 1) * segments + (b % segments); };
  for (int b = 0; b < segments; ++b) m.triangles.push_back({0, ring(1, b), ring(1, b + 1)});
  for (int a = 1; a + 1 < rings; ++a)
    for (int b = 0; b < segments; ++b) {
      m.triangles.push_back({ring(a, b), ring(a + 1, b), ring(a + 1, b + 1)});
      m.triangles.push_back({ring(a, b), ring(a + 1, b + 1), ring(a, b + 1)});
    }
  for (int b = 0; b < segments; ++b)
    m.triangles.push_back({south, ring(rings - 1, b + 1), ring(rings - 1, b)});
  return m;
}

}  // namespace plume
