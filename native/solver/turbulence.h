#pragma once
/// \file turbulence.h
/// Turbulence: a smooth random force that drifts over space and time and stirs the air, so a
/// plume from an even source folds, leans and curls the way room air makes real smoke do
/// (Blender's Turbulence force field on a Mantaflow domain, Houdini Pyro's Turbulence). The
/// force is a value-noise vector field g(x, t) ∈ [-1, 1]³ times the strength A; the pressure
/// projection that follows keeps its divergence-free part, the swirls.

#include "core/grid3.h"
#include "core/mac_grid3.h"
#include "solver/smoke_params.h"

#include <cstdint>

namespace plume {

/// g sampled on a lattice coarser than the cells (spacing max(h, λ/4): the noise has no detail
/// below λ/4 worth sampling), filled once per step and read by trilinear interpolation at the
/// faces, so the cost does not grow with the cells' count beyond the interpolation.
struct TurbulenceLattice {
  VectorGrid g;
  glm::vec3 origin{0.f};
  float spacing = 1.f;
};

/// u += dt A g(x_face, t) on the faces between fluid cells (A = params.turbulence, λ =
/// params.turbulenceScale, renewed params.turbulenceRate times a second). The same for the same
/// (params, time) on any thread count. `lattice` is scratch, resized when the domain changes.
void addTurbulence(MacGrid3& velocity, const FlagGrid* cellTypes, const SmokeParams& params,
                   double time, float dt, TurbulenceLattice& lattice);

}  // namespace plume
