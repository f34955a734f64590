#pragma once
/// \file surface_fit.h
/// The streak surface of one frame as a least-squares fit ([Smoke Surfaces] §3.3, Figure 6):
/// a B-spline surface on Blender's endpoint knots with a given control net nu × nv, usually
/// smaller than the particles, passing within a tolerance of every particle it is fitted to
/// while its control points stay on the smoke (an interpolating net through hundreds of
/// unevenly spaced particles swings metres away from them).

#include "nurbs/near_particles.h"
#include "nurbs/surface.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace plume {

/// Settings of the fit. Field names are the Python names in snake_case.
struct SurfaceFitParams {
  int orderU = 4;            ///< order along u (streaklines); the net uses min(orderU, nu)
  int orderV = 4;            ///< order across streaklines (v); min(orderV, nv)
  double smoothing = 1e-3;   ///< λ: weight of the second-difference penalty relative to the data
  /// α of the particles' parameters along a streakline (averagedChordParameters()): 1 chord
  /// length, ½ centripetal.
  double exponentU = 0.5;
  /// α across the streaklines.
  double exponentV = 0.5;
  /// The particle net along u: with one control point per particle slot (nu = particles) the
  /// control points are the particles themselves (slots not kept hold the nearest kept particle
  /// of the line, as in slotsInterpolated()), drawn at orderU, and particle a sits at the
  /// Greville abscissa ḡ_a of its control point. The sheet is then as smooth as orderU allows
  /// (C² when cubic) and cuts the corners of a zig-zag (|c_a − C(ḡ_a)| = |Δ²p_a|/6 on uniform
  /// cubic knots) instead of passing through every particle: chooseNetSize()'s last resort
  /// along u, instead of order 2.
  bool particleNetU = false;
  /// The particle net across: with nv = the lines that have kept particles, the control points
  /// are the lines' own curves (their u control points), line b at the Greville abscissa ḡ_b.
  bool particleNetV = false;

  /// Throws std::invalid_argument: orders in [2, 6], smoothing and exponents in [0, 1].
  void validate() const;
};

/// The particles of one surface at one frame: `lines` ordered streaklines (v) of `particles`
/// slots each (u, oldest first), points[b * particles + a]. keep[b * particles + a] = 1 marks
/// the particles the sheet goes through (the caller leaves out particles not yet emitted, and
/// those that left the simulated box); the other slots are ignored, whatever they hold.
struct StreakGrid {
  const glm::vec3* points = nullptr;
  const std::uint8_t* keep = nullptr;
  int particles = 0;
  int lines = 0;

  /// Throws std::invalid_argument unless lines, particles >= 1, both arrays are given, some
  /// particle is kept and the kept points are finite.
  void validate() const;
  std::size_t index(int line, int particle) const {
    return std::size_t(line) * std::size_t(particles) + std::size_t(particle);
  }
  const glm::vec3& at(int line, int particle) const { return points[index(line, particle)]; }
  bool kept(int line, int particle) const { return keep[index(line, particle)] != 0; }
};

/// One frame's fitted surface and where its particles sit on it.
struct SurfaceFit {
  NurbsSurface surface;
  /// u of every kept particle, [b * particles + a] (NaN for the others): the streakline's own
  /// chord length, mapped onto the drawn domain (oldest kept particle at its start), or with
  /// slotsInterpolated() the Greville abscissa of the particle's slot.
  std::vector<double> paramsU;
  /// v of every streakline (NaN for a line with no kept particle): its interpolation parameter,
  /// or averaged chord length across the lines' fitted curves when nv is smaller.
  std::vector<double> paramsV;
  /// max over kept particles of |S(u_ab, v_b) − q_ab|: an upper bound of each particle's
  /// distance to the sheet.
  double maxResidual = 0.0;
  /// max over control points of |P_ij − S(ḡ_i, ḡ_j)| (Greville abscissae): how far the net an
  /// artist edits strays from the sheet it shapes.
  double netDeviation = 0.0;
  /// max over control points of the distance to the nearest kept particle of the frame: how far
  /// the net strays from the smoke (filled by fitShot(); fitSurface() leaves it 0).
  double netToParticles = 0.0;
};

/// §3.3 as a fit, tensor product in two steps (Piegl & Tiller §9.4.3): each streakline, its kept
/// particles at centripetal chord-length parameters (coincident particles merged), becomes a
/// penalised least-squares curve (CurveFitter) with nu control points on Blender's endpoint
/// knots — except with one control point per particle slot (nu = particles) at order 2 or 3
/// (slotsInterpolated()): there particle a sits at the Greville abscissa ḡ_a of control point a
/// and the line is interpolated (§3.3's "each particle ... serves as a knot"), the slots of
/// particles not kept holding the nearest kept particle of the line (by slot), so at order 2
/// every control point is a particle; then every column of those control points becomes a curve across v with nv control
/// points: interpolated at interpolationParameters() when there are nv lines with kept particles
/// (§3.3's interpolation across the streaklines), else a penalised least-squares fit with the
/// lines at averaged chord-length parameters. Weights are 1. A direction with one distinct point
/// gives equal control points (constant along it). Lines with no kept particle take no part.
/// nu, nv >= 2. Throws std::invalid_argument on bad input.
SurfaceFit fitSurface(const StreakGrid& grid, int nu, int nv, const SurfaceFitParams& params);

/// True when fitSurface() makes each streakline's control points its particles
/// (params.particleNetU with nu = particles >= 2).
bool particleNetU(const StreakGrid& grid, int nu, const SurfaceFitParams& params);

/// True when fitSurface() interpolates each streakline with one control point per particle slot
/// at the slots' Greville abscissae (order along u of 2 or 3, nu = particles >= 2) instead of
/// fitting chord-length parameters: the low orders chooseNetSize() falls back to where the
/// lines scatter, at whose Greville abscissae the interpolation is exact and non-singular.
bool slotsInterpolated(const StreakGrid& grid, int nu, const SurfaceFitParams& params);

/// How well the streakline curves of the u step of fitSurface() alone fit: what the count along
/// u controls.
struct CurveFitQuality {
  double maxResidual = 0.0;   ///< max over kept particles of |C_b(u_ab) − q_ab|
  double netDeviation = 0.0;  ///< max over the curves' control points of |c_bj − C_b(ḡ_j)|
  /// max over the curves' control points of the distance to the nearest particle of `near`
  /// (0 when curveFitQuality() is given none).
  double netToParticles = 0.0;
};
CurveFitQuality curveFitQuality(const StreakGrid& grid, int nu, const SurfaceFitParams& params,
                                const NearParticles* near = nullptr);

/// The kept particles of grid, bucketed for netToParticles() (build once per frame).
NearParticles keptParticles(const StreakGrid& grid);

/// The u step of fitSurface() on its own: every line with kept particles as a curve of nu
/// control points (order min(params.orderU, nu)). It does not depend on nv or orderV, so a
/// search over those (chooseNetSize()) fits the lines once per frame and reuses them.
struct LineCurves {
  int nu = 0, order = 0;
  std::vector<int> lines;                 ///< the lines that have kept particles, in order
  std::vector<glm::dvec3> controlPoints;  ///< lines.size() × nu, row-major
  std::vector<double> paramsU;            ///< [b * particles + a], NaN where not kept
  std::vector<CurveFitQuality> quality;   ///< per entry of `lines`
};
LineCurves fitLines(const StreakGrid& grid, int nu, const SurfaceFitParams& params);

/// The v step: the surface of nv control points across `curves` (fitLines() of the same grid
/// and nu; params.orderU is not read again). fitSurface(g, nu, nv, p) is
/// fitAcross(g, fitLines(g, nu, p), nv, p), bit for bit.
SurfaceFit fitAcross(const StreakGrid& grid, const LineCurves& curves, int nv,
                     const SurfaceFitParams& params);

/// max over the surface's control points of the distance to the nearest kept particle of grid.
double netToParticles(const NurbsSurface& surface, const StreakGrid& grid);
/// The same, to the particles of `near` (keptParticles() of the frame).
double netToParticles(const NurbsSurface& surface, const NearParticles& near);

}  // namespace plume
