#pragma once
/// \file subdivision_export.h
/// Mesh export of a streak surface ([Smoke Surfaces] §3.3 notes that subdivision modelling
/// could also give a smooth surface once a base mesh exists — the control net is that mesh):
/// the NURBS control net refined with OpenSubdiv (Catmull-Clark, boundary EDGE_AND_CORNER)
/// into a smooth quad mesh carrying the §3.4 density as a per-vertex attribute.

#include <glm/glm.hpp>

#include <vector>

namespace plume {

/// Settings of the export. Field names are the Python names in snake_case.
struct SubdivisionParams {
  int level = 2;       ///< L: uniform Catmull-Clark refinement levels
  bool limit = true;   ///< move the level-L vertices onto the limit surface

  /// Throws std::invalid_argument: level in [0, 6].
  void validate() const;
};

/// The refined mesh: ((nu-1)·2^L + 1)((nv-1)·2^L + 1) vertices and (nu-1)(nv-1)·4^L quads
/// (OpenSubdiv's vertex order), with the density per vertex when one was given.
struct SubdividedMesh {
  std::vector<glm::vec3> vertices;
  std::vector<glm::ivec4> quads;
  std::vector<float> density;  ///< empty when no density was given
};

/// Refines the nu × nv control net (Blender's flat order, controlPoints[v * nu + u]; w is
/// ignored) made of the quads (u, v), (u+1, v), (u+1, v+1), (u, v+1). `densityImage` is optional:
/// a densityWidth × densityHeight image whose pixel (a (k_u+1), b (k_v+1)) belongs to control
/// point (a, b), i.e. a DensityMap of the same surface (or a plain nu × nv array, k = 0). Each
/// control point's image coordinates are refined like a primvar and the image is read
/// bilinearly there. Throws std::invalid_argument for bad sizes or settings.
SubdividedMesh subdivideControlNet(const std::vector<glm::vec4>& controlPoints, int nu, int nv,
                                   const SubdivisionParams& params,
                                   const std::vector<float>& densityImage = {}, int densityWidth = 0,
                                   int densityHeight = 0);

}  // namespace plume
