#pragma once
/// \file smoke_params.h
/// Every setting of the smoke/fire solver, with its paper symbol and default, and validate().

#include "core/sampling.h"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace plume {

/// Semi-Lagrangian (Stam 1999), BFECC (Kim et al. 2005, [Smoke Surfaces] §3.1) or MacCormack
/// (Selle et al. 2008: BFECC's accuracy with two interpolation passes instead of three).
enum class Advection { SemiLagrangian, Bfecc, MacCormack };

/// How a semi-Lagrangian step traces a sample back through the velocity field (Stam 1999 §3.2):
/// the explicit midpoint rule (RK2, second order in time: one more velocity sample halfway), or
/// one Euler step with the velocity at the sample itself, first order, which on the MAC grid is
/// an exact average of 2 or 4 faces and needs no interpolation (Mantaflow's default trace).
enum class Trace { Midpoint, Euler };

/// A side of the domain is open ([Smoke Surfaces]'s default) or a wall (Closed: no flow
/// through it, u·n = 0; scalars and tangential velocity zero-gradient).
/// Open: the ambient air lies beyond it (inflow.h). p = 0 outside; what flows out leaves with
/// zero gradient; what flows in is ambient air: ρ = F = S = 0, T = T_amb, velocity 0 (or the
/// wind's, when wind_strength > 0), so air enters only where the pressure projection draws it
/// in (or the wind blows it in), never by copying the inside's values back in.
enum class Boundary { Open, Closed };

/// Sides in the order -x, +x, -y, +y, -z, +z.
enum Side { kNegX = 0, kPosX, kNegY, kPosY, kNegZ, kPosZ };

/// Settings of one bake. Units: metres, seconds. Field names are the Python names in snake_case.
struct SmokeParams {
  // --- Domain ---
  glm::ivec3 resolution{32, 32, 32};  ///< cells per axis
  float cellSize = 1.f / 32.f;         ///< Δx, metres
  glm::vec3 origin{0.f};               ///< world position of the domain's minimum corner
  std::array<Boundary, 6> boundaries{Boundary::Open, Boundary::Open, Boundary::Open,
                                     Boundary::Open, Boundary::Closed, Boundary::Open};

  // --- Adaptive domain (adaptive_domain.h; Mantaflow's Adaptive Domain) ---
  /// Step only the box around the smoke (Mantaflow: use_adaptive_domain).
  bool adaptiveDomain = false;
  /// Cells of air around the smoke in the box (Mantaflow: adapt_margin).
  int adaptiveMargin = 6;
  /// ρ, |T - T_amb|, F or S above which a cell holds smoke (Mantaflow: adapt_threshold).
  float adaptiveThreshold = 0.005f;

  // --- Time ---
  float frameDt = 1.f / 24.f;  ///< seconds per frame (1/fps × time scale)
  int substeps = 1;            ///< minimum steps per frame
  bool useCfl = true;          ///< add steps so that no cell moves more than `cfl` cells per step
  float cfl = 4.f;             ///< CFL number for the adaptive steps

  // --- Advection ---
  Advection advection = Advection::Bfecc;
  Interpolation interpolation = Interpolation::MonotonicCubic;
  /// Fast Velocity: carry the velocity with trilinear samples whatever `interpolation` is (the
  /// scalars, what renders, keep it): with BFECC the step is ~2× cheaper at 64³-256³ and keeps
  /// nearly what cubic BFECC keeps of a smooth field (advection_velocity_test.cpp); the
  /// small-scale motion differs, not its amount (streaklines scatter alike). Off: cubic velocity.
  bool linearVelocity = true;
  Trace trace = Trace::Midpoint;  ///< back-trace order (Euler: Mantaflow's first-order trace)
  /// Restore Σρ, ΣF, ΣS and the heat Σ(T - T_amb) after advection (minus outflow), see
  /// mass_conservation.h.
  bool conserveMass = true;

  // --- Forces (Fedkiw 2001 eq. 8, 9) ---
  glm::vec3 gravity{0.f, 0.f, -9.81f};  ///< g; buoyancy acts against it
  float alpha = 1.f;  ///< α: buoyancy from density (Blender's sign: > 0 makes dense smoke rise)
  float beta = 1.f;   ///< β: buoyancy from heat, f = -g (α ρ + β (T - T_amb))
  float ambientTemperature = 0.f;  ///< T_amb (T_0 of the fire paper)
  glm::vec3 wind{0.f};  ///< wind velocity the air is pulled towards (m/s)
  float windStrength = 0.f;   ///< k_w: f_wind = k_w (u_wind - u), 1/s
  float vorticity = 0.2f;     ///< ε: vorticity confinement strength (Fedkiw 2001 eq. 11)
  float densityDissipation = 0.f;  ///< fraction of density lost per second
  /// Turbulence (turbulence.h): A, m/s², strength of the drifting random force; 0 = off.
  float turbulence = 0.f;
  float turbulenceScale = 0.3f;  ///< λ, metres: size of the turbulence's swirls
  float turbulenceRate = 0.5f;   ///< times a second the turbulence's pattern renews

  // --- Pressure projection ---
  float pressureTolerance = 1e-4f;  ///< relative residual |r|/|b| at which MGPCG stops
  int maxPressureIterations = 200;

  // --- Combustion ([Graph Fire Synthesis] eqs. 1-5) ---
  bool combustion = false;
  float burnRate = 4.f;         ///< r: fuel burnt per second, dF/dt = -r F
  float sootYield = 0.5f;       ///< k_S: soot made per unit fuel burnt
  float heatYield = 4.f;        ///< k_T: heat made per unit fuel burnt
  float conductivity = 0.f;     ///< κ: thermal conductivity, m²/s
  float coolingRate = 1.f;      ///< c: cooling, c ((T - T_0)/(T_max - T_0))^4 per second
  float maxTemperature = 4.f;   ///< T_max
  float expansion = 1.f;        ///< φ: divergence per unit of fuel burnt per second (eq. 1)
  /// ε_f: vorticity confinement added where fuel burns, ε + ε_f min(F, 1) (forces.h; Mantaflow's
  /// Flame Vorticity): the flames curl, the smoke above them stays smooth.
  float flameVorticity = 0.f;

  // --- Run ---
  std::uint64_t seed = 0;
  int threads = 0;  ///< 0: all cores

  /// Throws std::invalid_argument naming the setting and its accepted range.
  void validate() const;
  /// World-space size of the domain.
  glm::vec3 size() const { return glm::vec3(resolution) * cellSize; }
};

/// Upper bound on cells a bake may allocate (about 64 bytes each); validate() rejects more.
constexpr double kMaxCells = 512.0 * 512.0 * 512.0;

/// Accepted range [lo, hi] of one numeric setting of SmokeParams, by its Python name. The one
/// definition: validate() checks against it, and the add-on's properties and bake-time messages
/// read it (SmokeParams.ranges()).
struct SettingRange {
  const char* name;
  double lo;
  double hi;
};

/// Every bounded numeric setting of SmokeParams (resolution is per axis).
const std::vector<SettingRange>& smokeSettingRanges();
/// The range of setting `name`; std::out_of_range when it has none.
const SettingRange& smokeSettingRange(const std::string& name);

}  // namespace plume
