#pragma once
/// \file adaptive_domain.h
/// The adaptive domain (Mantaflow's "Adaptive Domain"; SmokeParams::adaptiveDomain, off by
/// default): each step runs on the box around the cells that hold smoke, heat, fuel or soot
/// above adaptive_threshold (|T - T_amb| for heat), united with the cells the sources and point
/// emitters fill and the moving obstacles' cells, grown by adaptive_margin cells and rounded
/// out to blocks of kActiveBoxBlock cells (active_box.h), clamped to the domain. Outside the box
/// the air is at rest (or moves with the wind) and at ambient temperature.
///
/// Design:
/// - The full solver keeps its full-domain grids as the public state, so every reader and
///   writer (VDB cache, state file and resume, tracers, the other pipelines) stays world-aligned
///   and unchanged: cells outside the box hold the background values and cost the sparse VDB
///   grids nothing.
/// - The steps run on an inner SmokeSolver whose resolution is the box and whose origin is the
///   box's corner. Its sides that lie on the domain's sides keep the domain's boundary types;
///   its inner sides are Open (inflow.h): p = 0 and ambient air at rest beyond them. When the box
///   is the whole domain its params equal the full solver's, and the result is the full
///   domain's bit for bit.
/// - The box is recomputed before every step (CFL sub-steps too): at the start of a frame from
///   the full grids, then from the inner solver's (outside the box everything is background). So
///   it depends on the state only, and a bake resumed from a state file continues identically.
/// - At the start of each frame the state is copied into the box (the public grids may have been
///   written, e.g. by readState) and the frame's emitters are remapped into it (source and
///   obstacle cell indices, the wind field cropped); at its end the box is copied back. A box
///   change mid-frame copies back, resets what the box leaves behind to ambient air, builds the
///   inner solver for the new box and copies in. With a StepObserver the box is copied back
///   after every step, so the observer reads the full grids.
/// - Every copy carries the pressure too: it is the initial guess of the next pressure solve.

#include "solver/active_box.h"

#include <memory>

namespace plume {

class SmokeSolver;
struct StepStats;

class AdaptiveDomain {
 public:
  AdaptiveDomain();
  ~AdaptiveDomain();

  /// Start of a frame: the box from `full`'s state, the inner solver for it (kept when the box is
  /// unchanged), the frame's emitters and the state copied in.
  void beginFrame(SmokeSolver& full);
  /// One step of length dt on the box, re-boxing first when the smoke has moved.
  void step(SmokeSolver& full, float dt);
  /// Copies the box's state back into `full`'s grids.
  void syncBack(SmokeSolver& full) const;
  /// Figures of the inner solver's last step.
  const StepStats& lastStats() const;
  /// The current box, in cells of the full domain.
  const ActiveBox& box() const { return mBox; }

 private:
  ActiveBox boxFor(const SmokeSolver& full, bool fromInner) const;
  void rebox(SmokeSolver& full, const ActiveBox& box);
  void setEmitters(const SmokeSolver& full);
  void copyIn(const SmokeSolver& full);
  /// Ambient air (at rest or with the wind, T_amb, p = 0) everywhere outside `box`.
  void resetOutside(SmokeSolver& full, const ActiveBox& box) const;

  std::unique_ptr<SmokeSolver> mInner;
  ActiveBox mBox;
};

}  // namespace plume
