#pragma once
/// \file shot_fit.h
/// The streak surface of a whole shot ([Smoke Surfaces] §3.3): Blender keeps one control-net
/// topology per object, so the counts nu × nv are chosen once, as the smallest that fit every
/// frame within a tolerance, and every frame is fitted with them (fitSurface()).

#include "nurbs/surface_fit.h"

#include <vector>

namespace plume {

/// Settings of the shot's fit. Field names are the Python names in snake_case.
struct ShotFitParams {
  SurfaceFitParams fit;
  /// ε: largest distance allowed between a kept particle and the sheet, world units (the
  /// add-on passes a fraction of the cell size).
  double tolerance = 0.01;
  /// δ: largest distance allowed between a control point and the sheet at its Greville
  /// abscissae (SurfaceFit::netDeviation), world units: keeps the net an artist edits on the
  /// smoke where the streaklines curl (a coarse net that fits within ε still cuts corners far
  /// outside the curls; an interpolating one swings off).
  double netTolerance = 0.04;
  /// ν: largest distance allowed between a control point and the nearest kept particle of its
  /// frame, world units (the add-on passes 3 cells): the control point an artist grabs sits among
  /// the particles it shapes, even where they are too sparse for δ to say so. On a frame whose
  /// streaklines have consecutive kept particles farther apart than 2ν (a fast source early in
  /// its shot), half that largest gap instead: a control point on the sheet between two such
  /// particles cannot be nearer either.
  double particleTolerance = 0.06;

  /// Throws std::invalid_argument: fit.validate(), the three tolerances finite and > 0.
  void validate() const;
};

/// The chosen control counts (and order across the streaklines) and the worst fit they give.
struct NetSize {
  int nu = 2;
  int nv = 2;
  int orderU = 2;  ///< the order used along the streaklines (at most fit.orderU)
  int orderV = 2;  ///< the order used across the streaklines (at most fit.orderV)
  bool particleNetU = false;  ///< SurfaceFitParams::particleNetU: the control points are the particles
  bool particleNetV = false;  ///< SurfaceFitParams::particleNetV: the rows are the lines' curves
  double maxResidual = 0.0;     ///< max over frames of SurfaceFit::maxResidual
  double netDeviation = 0.0;    ///< max over frames of SurfaceFit::netDeviation
  double netToParticles = 0.0;  ///< max over frames of SurfaceFit::netToParticles
};

/// Counts for a shot of frames (all with the same particles and lines; the kept ones may
/// change): along u the smallest nu in [min(order_u, P), P] (P = particles, at least 2) for
/// which every frame's streakline curves pass within ε of their particles and have their
/// control points within δ of the curve and within ν of a particle (curveFitQuality(); ν of
/// the frame, see ShotFitParams::particleTolerance), by
/// bisection on ε and δ, then the first of that count and the 8 above it that meets ν too (ν
/// is not monotone in the count: a control point may land mid-gap between sparse particles at
/// one count and beside one at the next), else P; then, with that nu, the smallest nv in
/// [min(order_v, L), L] (L = lines, at least 2) for which every frame's surface does (fitSurface(), netToParticles()). Where the lines
/// scatter along u (the top of a plume late in its shot: consecutive particles many cells apart,
/// zig-zagging) even P control points at order_u miss, and the order along them drops to 3: at
/// nu = P that interpolates every particle at its slot's Greville abscissa (slotsInterpolated()).
/// Where that misses too, the particle net (SurfaceFitParams::particleNetU) at order_u: every
/// control point is a particle (ν = 0) and the sheet stays C² (no facets in a close-up, Figure
/// 7), cutting the corners of the zig-zags by |Δ²p|/6 (ε and δ give way there; order 2 drew the
/// same control points as flat facets through the particles). Where the lines are too crumpled
/// across (a smooth sheet through them swings beyond δ even when it interpolates them: the
/// greedy order of many streaklines zig-zags), the order across them drops likewise (4, 3, then
/// the particle net across, whose rows are the lines' own curves, where its sheet stays within ν
/// of every kept particle, then 2: zig-zagging neighbours are a folded sheet, not scatter) before
/// nv is chosen. Where
/// even the largest count misses, the largest is used; NetSize says what it gives. Frames are
/// fitted in parallel; the result does not depend on the thread count.
NetSize chooseNetSize(const std::vector<StreakGrid>& frames, const ShotFitParams& params);

/// fitSurface() of every frame with the net `size` (its counts and orders; the rest of the
/// settings from `params`), with netToParticles() filled in; in parallel, deterministic.
std::vector<SurfaceFit> fitShot(const std::vector<StreakGrid>& frames, const NetSize& size,
                                const SurfaceFitParams& params);

}  // namespace plume
