#pragma once
/// \file bindings.h
/// One bind function per component; module.cpp calls them in order (enums first, since the
/// other bindings use them as argument types and defaults). The conversions they share are in
/// convert.h.

#include <pybind11/pybind11.h>

namespace plume::bindings {

/// SmokeParams, SourceSettings (bindSolverParams, bind_solver_params.cpp), then SmokeSolver
/// (bind_solver.cpp).
void bindSolver(pybind11::module_& m);
void bindSolverParams(pybind11::module_& m);
/// vdb_grid_names, read_vdb_grid (bind_io.cpp).
void bindIo(pybind11::module_& m);
/// Streak-surface NURBS: interpolation, evaluation, tessellation, density map, OpenSubdiv export
/// (bind_nurbs.cpp).
void bindNurbs(pybind11::module_& m);
/// Least-squares streak surfaces: fit_surface, fit_streak_shot, control_point_frames
/// (bind_nurbs_fit.cpp).
void bindNurbsFit(pybind11::module_& m);
/// Point sources, StreakTracer, streak files (bind_streak.cpp).
void bindStreak(pybind11::module_& m);
/// StreakFrames, sparse StreakDistances, threshold, clusters, counts, greedy order
/// (bind_streak_clusters.cpp).
void bindStreakClusters(pybind11::module_& m);
/// Mantaflow cache frames, volumes and the tracer driven by them (bind_mantaflow.cpp).
void bindMantaflow(pybind11::module_& m);
/// Toon smoke: params and fields (bind_toon.cpp), then particles, billboards, depth
/// differences, toon files (bindToonParticles, bind_toon_particles.cpp).
void bindToon(pybind11::module_& m);
void bindToonParticles(pybind11::module_& m);
/// PathlineLayout and PathlineGroup, the flow-graph node type (bind_pathline_group.cpp).
void bindPathlineGroup(pybind11::module_& m);
/// Flow-graph fire data and synthesis: PathlineParams, PathlineRecorder, PathlineFile
/// (bindFlowgraphPathlines, bind_flowgraph_pathlines.cpp), then Synthesizer, VelocityField,
/// FireRasterParams, write_fire_vdb (bind_flowgraph_synth.cpp).
void bindFlowgraphSynth(pybind11::module_& m);
void bindFlowgraphPathlines(pybind11::module_& m);
/// Flow graph: FlowGraphParams, cost_matrix, FlowGraph, RandomWalk, cost_matrix_image
/// (bind_flowgraph_graph.cpp).
void bindFlowgraphGraph(pybind11::module_& m);
/// Flame bake helpers: mesh_signed_distance for obstacles (bind_flames_bake.cpp).
void bindFlamesBake(pybind11::module_& m);
/// Structural flames, structure: FlameParams, FlameSource, wind fields, obstacle SDFs,
/// FlameSystem, Spine, spine_resample (bind_flames_structure.cpp).
void bindFlamesStructure(pybind11::module_& m);
/// Structural flames, shape and render: FlameProfile, FlameCamera, FlameShaper, write_flames_vdb
/// (bind_flames_shape.cpp).
void bindFlamesShape(pybind11::module_& m);

}  // namespace plume::bindings
