/// \file bind_flowgraph_pathlines.cpp
/// Flow-graph fire, recording side ([Graph Fire Synthesis] §4.2): the pathline settings, the
/// pathline recorder of a fire bake with the file it writes, and complete pathline files read
/// node by node. Conversions and docstrings only; frames, file reads and writes release the GIL.

#include "bindings/bindings.h"
#include "bindings/convert.h"

#include "flowgraph/pathline_recorder.h"
#include "flowgraph/pathline_file.h"

#include <pybind11/stl.h>

#include <memory>

namespace py = pybind11;

namespace plume::bindings {
namespace {

/// A 1-D array of linear cell indices as a CellSet (ValueError for negative ones).
CellSet cellsArg(const py::object& o) {
  const Int64ArrayC a = Int64ArrayC::ensure(o);
  if (!a || a.ndim() != 1) throw py::value_error("fuel_cells must be a 1-D array of cell indices");
  CellSet cells;
  for (py::ssize_t n = 0; n < a.size(); ++n) {
    const long long c = a.data()[n];
    if (c < 0 || c > 0xffffffffLL) throw py::value_error("fuel_cells holds an index outside the grid");
    cells.cells.push_back(std::uint32_t(c));
  }
  return cells;
}

/// A recorder writing its groups to a pathline file as they complete (one per bake).
struct PathlineBake {
  std::unique_ptr<PathlineFileWriter> writer;
  std::unique_ptr<PathlineRecorder> recorder;
};

void bindRecorder(py::module_& m) {
  py::class_<PathlineParams> p(m, "PathlineParams", "Pathline sampling of a fire bake (§4.2).");
  p.def(py::init([](int nodesPerFrame, float lifetime) {
          PathlineParams s;
          s.nodesPerFrame = nodesPerFrame;
          s.lifetime = lifetime;
          s.validate();
          return s;
        }),
        py::arg("nodes_per_frame") = 2, py::arg("lifetime") = 1.f,
        "ValueError on nodes_per_frame outside [1, 64] or a lifetime that is not > 0 s.");
  p.def_readonly("nodes_per_frame", &PathlineParams::nodesPerFrame,
                 "Node steps per frame: Δt_n = frame_dt / nodes_per_frame. Reproduction is accurate "
                 "when the fastest particles cross about one cell per node step (§4.1: Δt = 0.5 Δx / U).");
  p.def_readonly("lifetime", &PathlineParams::lifetime, "t_max, seconds: L = round(t_max / Δt_n).");
  p.def("samples", &PathlineParams::samples, py::arg("frame_dt"), "L for frames of frame_dt seconds.");

  py::class_<PathlineBake> r(
      m, "PathlineRecorder",
      "Records the pathline groups of a fire bake (§4.2-4.3) into a pathline file while the solver "
      "runs: at every node step Δt_n, |Ω| particles seeded at spacing Δx/2 in the fuel cells, "
      "integrated with RK4 across the solver's substeps, sampled L times. Groups are appended as "
      "they complete; finish() makes the file complete (until then only '<path>.partial' exists).");
  r.def(py::init([](const PathlineParams& params, const SmokeParams& smoke, const py::object& cells,
                    const py::object& path, bool float16) {
          auto bake = std::make_unique<PathlineBake>();
          // The sink reaches the writer through the bake, whose address Python's holder keeps.
          bake->recorder = std::make_unique<PathlineRecorder>(
              params, smoke, cellsArg(cells),
              [raw = bake.get()](const PathlineGroup& g, const std::vector<glm::vec3>&) {
                raw->writer->append(g);
              });
          PathlineFileInfo info;
          info.layout = bake->recorder->layout();
          info.resolution = smoke.resolution;
          info.cellSize = smoke.cellSize;
          info.origin = smoke.origin;
          info.nodesPerFrame = params.nodesPerFrame;
          info.float16 = float16;
          bake->writer = withPath(path, [&](const std::string& file) {
            return std::make_unique<PathlineFileWriter>(file, info);
          });
          return bake;
        }),
        py::arg("params"), py::arg("smoke"), py::arg("fuel_cells"), py::arg("path"),
        py::arg("float16") = false,
        "params: PathlineParams; smoke: the bake's SmokeParams; fuel_cells: linear indices of the "
        "cells where fuel is injected (source_cells() of every fuel source); path: the pathline "
        "file (pathlines.bin in the bake folder). ValueError on bad settings or no fuel cell; "
        "RuntimeError naming the file if it cannot be written.");
  r.def(
      "advance_frame",
      [](PathlineBake& b, SmokeSolver& solver) {
        py::gil_scoped_release release;
        return solver.advanceFrame(b.recorder.get());
      },
      py::arg("solver"),
      "solver.advance_frame() with the recorder following every substep. Releases the GIL. "
      "Returns False when the solver or the recorder was cancelled (discard both).");
  r.def("finish", [](PathlineBake& b) {
          py::gil_scoped_release release;
          b.writer->finish();
        },
        "Writes the node table and renames the file to its path (the groups still young are "
        "dropped: they lack samples).");
  r.def("discard", [](PathlineBake& b) { b.writer->discard(); },
        "Removes the partial file (a cancelled bake).");
  r.def("cancel", [](PathlineBake& b) { b.recorder->cancel(); },
        "Thread-safe: a running advance_frame() returns False before its next step.");
  r.def_property_readonly("layout", [](const PathlineBake& b) { return b.recorder->layout(); });
  r.def_property_readonly("seeds", [](const PathlineBake& b) { return rowsArray(b.recorder->seeds()); },
                          "Ω: (|Ω|, 3) float32 world positions.");
  r.def_property_readonly("groups_seeded", [](const PathlineBake& b) { return b.recorder->groupsSeeded(); });
  r.def_property_readonly("groups_completed",
                          [](const PathlineBake& b) { return b.recorder->groupsCompleted(); },
                          "Nodes written so far.");
  r.def_property_readonly("path", [](const PathlineBake& b) { return b.writer->path(); });
  r.def_property_readonly("partial_path", [](const PathlineBake& b) { return b.writer->partialPath(); });
}

void bindFile(py::module_& m) {
  py::class_<PathlineFile> f(m, "PathlineFile",
                             "A complete pathline file, read lazily: open() reads its header and "
                             "node table, read_group() one node.");
  f.def_static("open", [](const py::object& path) { return withPath(path, PathlineFile::open); },
               py::arg("path"),
               "RuntimeError naming the file when it is missing, incomplete, truncated or corrupt.");
  f.def_property_readonly("path", &PathlineFile::path);
  f.def_property_readonly("layout", &PathlineFile::layout);
  f.def_property_readonly("node_count", &PathlineFile::nodeCount);
  f.def_property_readonly("bytes_per_node", &PathlineFile::bytesPerNode);
  f.def_property_readonly("float16", [](const PathlineFile& p) { return p.info().float16; });
  f.def_property_readonly("nodes_per_frame", [](const PathlineFile& p) { return p.info().nodesPerFrame; });
  f.def_property_readonly("resolution", [](const PathlineFile& p) { return vec3Tuple(p.info().resolution); });
  f.def_property_readonly("cell_size", [](const PathlineFile& p) { return p.info().cellSize; });
  f.def_property_readonly("origin", [](const PathlineFile& p) { return vec3Tuple(p.info().origin); });
  f.def("read_group", [](const PathlineFile& p, int k, int state) {
          py::gil_scoped_release release;
          return p.readGroup(k, state);
        },
        py::arg("node"), py::arg("state") = 0,
        "Node k as a PathlineGroup (state copied into it). IndexError for a bad k, RuntimeError "
        "naming the file for a corrupt block.");
}

}  // namespace

void bindFlowgraphPathlines(py::module_& m) {
  bindRecorder(m);
  bindFile(m);
}

}  // namespace plume::bindings
