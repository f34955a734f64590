#pragma once
/// \file streak_frames.h
/// Snapshot dicts (as StreakTracer.snapshot() and read_streak_file() give them) as C++ streak
/// frames; shared by bind_streak.cpp (which defines them) and bind_streak_clusters.cpp.

#include "tracers/streak_frame.h"

#include <pybind11/pybind11.h>

#include <string>
#include <vector>

namespace plume::bindings {

/// Every snapshot of a sequence ("snapshot t" in errors, ValueError on inconsistent sizes). With
/// positionsOnly, density and outside are neither read nor kept (left empty), for the clustering
/// of §3.3, which reads counts, positions and groups only.
std::vector<StreakFrame> toStreakFrames(const pybind11::sequence& snapshots, bool positionsOnly);

/// A one-dimensional integer array-like as ints (ValueError naming it outside int32).
std::vector<int> toIntVector(const pybind11::object& values, const std::string& name);

}  // namespace plume::bindings
