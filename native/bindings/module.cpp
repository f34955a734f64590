/// \file module.cpp
/// The Python module plume._native: enums shared by every component, then each component's
/// bindings. Only conversions and docstrings live in bindings/; the work is in the core.

#include "bindings/bindings.h"

#include "flames/flame_params.h"
#include "flames/flow_noise.h"
#include "flames/kolmogorov_noise.h"
#include "flames/spine_noise.h"
#include "flowgraph/pathline_recorder.h"
#include "solver/smoke_params.h"
#include "tracers/point_sources.h"
#include "tracers/streak_tracer.h"
#include "solver/smoke_solver.h"

namespace py = pybind11;

PYBIND11_MODULE(_native, m) {
  m.doc() =
      "Plume native core: smoke/fire grid solver (Stam 1999; Fedkiw, Stam & Jensen 2001; the\n"
      "combustion model of Graph-based Fire Synthesis) and its VDB/state files.\n"
      "Arrays are float32 copies shaped (nx, ny, nz), indexed [i, j, k]; cell (i, j, k) is centred\n"
      "at origin + (i + 0.5, j + 0.5, k + 0.5) * cell_size.";
  m.attr("__version__") = "0.1.0";
  m.def(
      "setting_ranges",
      [] {
        py::dict d;
        for (const plume::SettingRange& r : plume::smokeSettingRanges())
          d[r.name] = py::make_tuple(r.lo, r.hi);
        d["emission_period"] = py::make_tuple(1, plume::kMaxEmissionPeriod);
        d["point_sources"] = py::make_tuple(1, plume::kMaxPointsPerCell);
        d["pathline_nodes_per_frame"] = py::make_tuple(1, plume::kMaxNodesPerFrame);
        d["flames.points"] = py::make_tuple(plume::kMinSpinePoints, plume::kMaxSpinePoints);
        // The noises (§4.2, §4.5): a scale is > 0 (lower bound excluded), a drift per component.
        d["flames.flow_noise"] = py::make_tuple(0.0, plume::kMaxFlowNoiseAmplitude);
        d["flames.flow_noise_scale"] = py::make_tuple(0.0, plume::kMaxFlowNoiseScale);
        d["flames.flow_noise_frequency"] = py::make_tuple(0.0, plume::kMaxFlowNoiseFrequency);
        d["flames.flow_noise_rotation"] = py::make_tuple(0.0, plume::kMaxFlowNoiseRotation);
        d["flames.kolmogorov"] = py::make_tuple(0.0, plume::kMaxKolmogorovAmplitude);
        d["flames.kolmogorov_scale"] = py::make_tuple(0.0, plume::kMaxKolmogorovScale);
        d["flames.kolmogorov_frequency"] = py::make_tuple(0.0, plume::kMaxKolmogorovFrequency);
        d["flames.kolmogorov_drift"] = py::make_tuple(-plume::kMaxKolmogorovDrift, plume::kMaxKolmogorovDrift);
        d["flames.spine_noise"] = py::make_tuple(0.0, plume::kMaxSpineNoiseAmplitude);
        d["flames.spine_noise_scale"] = py::make_tuple(0.0, plume::kMaxSpineNoiseScale);
        d["flames.spine_noise_frequency"] = py::make_tuple(0.0, plume::kMaxSpineNoiseFrequency);
        d["flames.spine_noise_drift"] = py::make_tuple(-plume::kMaxSpineNoiseDrift, plume::kMaxSpineNoiseDrift);
        return d;
      },
      "{setting: (lo, hi)}: the accepted range of every bounded setting the core checks "
      "(SmokeParams.ranges(), the streak tracer's emission_period, point sources per cell, "
      "pathline nodes per frame, a flame spine's control points, the flames' noise settings), the one definition the add-on's properties and messages read.");

  py::enum_<plume::Advection>(m, "Advection",
                              "Advection scheme: semi-Lagrangian (Stam 1999), BFECC (Kim et al. "
                              "2005, smoke_surfaces §3.1) or MacCormack (Selle et al. 2008).")
      .value("SEMI_LAGRANGIAN", plume::Advection::SemiLagrangian)
      .value("BFECC", plume::Advection::Bfecc)
      .value("MACCORMACK", plume::Advection::MacCormack);
  py::enum_<plume::Interpolation>(
      m, "Interpolation",
      "How grids are sampled between samples: trilinear or monotonic cubic (Fedkiw 2001 §5).")
      .value("LINEAR", plume::Interpolation::Linear)
      .value("MONOTONIC_CUBIC", plume::Interpolation::MonotonicCubic);
  py::enum_<plume::Boundary>(m, "Boundary",
                             "A domain side: OPEN (air, p = 0, outflow) or CLOSED (a wall).")
      .value("OPEN", plume::Boundary::Open)
      .value("CLOSED", plume::Boundary::Closed);
  py::enum_<plume::Slip>(m, "Slip",
                         "Obstacle wall condition: NO_SLIP drags the air to the obstacle's "
                         "velocity, FREE_SLIP only stops the normal part.")
      .value("NO_SLIP", plume::Slip::NoSlip)
      .value("FREE_SLIP", plume::Slip::FreeSlip);

  plume::bindings::bindSolver(m);
  plume::bindings::bindIo(m);
  plume::bindings::bindNurbs(m);
  plume::bindings::bindNurbsFit(m);
  plume::bindings::bindStreak(m);
  plume::bindings::bindStreakClusters(m);
  plume::bindings::bindMantaflow(m);
  plume::bindings::bindToon(m);
  plume::bindings::bindPathlineGroup(m);
  plume::bindings::bindFlowgraphSynth(m);
  plume::bindings::bindFlowgraphGraph(m);
  plume::bindings::bindFlamesBake(m);
  plume::bindings::bindFlamesStructure(m);
  plume::bindings::bindFlamesShape(m);
}
