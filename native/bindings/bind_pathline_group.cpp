/// \file bind_pathline_group.cpp
/// PathlineLayout and PathlineGroup (flowgraph/pathline_group.h, [Graph Fire Synthesis] §4.3
/// eq. 7), the node type shared by the flow-graph bindings (bind_flowgraph_*.cpp). The arrays are
/// NumPy views into the group (alive as long as any view is).

#include "bindings/bindings.h"
#include "bindings/convert.h"

#include "flowgraph/pathline_group.h"

#include <cmath>
#include <cstring>

namespace py = pybind11;

namespace plume::bindings {
namespace {

/// A read-only view of `shape` floats at `data`, kept alive by the Python object `owner`.
py::array view(const py::object& owner, const float* data, std::vector<py::ssize_t> shape) {
  py::array_t<float> a(shape, data, owner);
  a.attr("setflags")(py::arg("write") = false);
  return std::move(a);
}

/// Copies an array of exactly `shape` into `out` (ValueError naming it otherwise).
template <typename T>
void copyExact(const py::object& o, const std::vector<py::ssize_t>& shape, std::vector<T>& out,
               const char* name) {
  const FloatArrayC a = FloatArrayC::ensure(o);
  bool ok = a && a.ndim() == py::ssize_t(shape.size());
  for (std::size_t d = 0; ok && d < shape.size(); ++d) ok = a.shape(py::ssize_t(d)) == shape[d];
  if (!ok) {
    std::string s = std::string(name) + " must be a float array of shape (";
    for (std::size_t d = 0; d < shape.size(); ++d) s += (d ? ", " : "") + std::to_string(shape[d]);
    throw py::value_error(s + ")");
  }
  out.resize(std::size_t(a.size()) * sizeof(float) / sizeof(T));
  if (a.size()) std::memcpy(out.data(), a.data(), std::size_t(a.size()) * sizeof(float));
}

}  // namespace

void bindPathlineGroup(py::module_& m) {
  py::class_<PathlineLayout> l(m, "PathlineLayout",
                               "The shape of every pathline group of a flow graph (§4.2): "
                               "|Ω| particles, L samples Δt_n apart.");
  l.def(py::init([](int particles, int samples, float sampleDt) {
          if (particles < 1 || samples < 2 || !(sampleDt > 0.f) || !std::isfinite(sampleDt))
            throw py::value_error("PathlineLayout needs particles >= 1, samples >= 2 and a finite "
                                  "sample_dt > 0");
          return PathlineLayout{particles, samples, sampleDt};
        }),
        py::arg("particles"), py::arg("samples"), py::arg("sample_dt"));
  l.def_readonly("particles", &PathlineLayout::particles, "|Ω|: seeds per group.");
  l.def_readonly("samples", &PathlineLayout::samples, "L: samples per pathline.");
  l.def_readonly("sample_dt", &PathlineLayout::sampleDt, "Δt_n: seconds between samples.");
  l.def("__eq__", [](const PathlineLayout& a, const PathlineLayout& b) { return a == b; });
  l.def("__repr__", [](const PathlineLayout& a) {
    return "PathlineLayout(particles=" + std::to_string(a.particles) + ", samples=" +
           std::to_string(a.samples) + ", sample_dt=" + std::to_string(a.sampleDt) + ")";
  });

  py::class_<PathlineGroup> g(
      m, "PathlineGroup",
      "A flow-graph node (§4.3, eq. 7): the pathlines of the particles seeded at node step "
      "`step` of fire bake `state`, with velocity, density and temperature sampled L times, "
      "Δt_n apart. A particle that left the domain samples zeros from then on.");
  g.def(py::init([](const py::object& start, const py::object& velocity, const py::object& density,
                    const py::object& temperature, float sampleDt, int state, int step) {
          const FloatArrayC s = FloatArrayC::ensure(start);
          const FloatArrayC d = FloatArrayC::ensure(density);
          if (!s || s.ndim() != 2 || s.shape(1) != 3)
            throw py::value_error("start must be a float array of shape (particles, 3)");
          if (!d || d.ndim() != 2 || d.shape(0) != s.shape(0))
            throw py::value_error("density must be a float array of shape (particles, samples)");
          PathlineGroup out;
          out.state = state;
          out.step = step;
          const py::ssize_t p = s.shape(0), l = d.shape(1);
          if (p < 1 || l < 2 || !(sampleDt > 0.f))
            throw py::value_error("a pathline group needs >= 1 particle, >= 2 samples, sample_dt > 0");
          out.layout = PathlineLayout{int(p), int(l), sampleDt};
          copyExact(start, {p, 3}, out.start, "start");
          copyExact(velocity, {p, l, 3}, out.velocity, "velocity");
          copyExact(density, {p, l}, out.density, "density");
          copyExact(temperature, {p, l}, out.temperature, "temperature");
          return out;
        }),
        py::arg("start"), py::arg("velocity"), py::arg("density"), py::arg("temperature"),
        py::arg("sample_dt"), py::arg("state") = 0, py::arg("step") = 0,
        "A group from arrays: start (P, 3), velocity (P, L, 3), density and temperature (P, L).");
  g.def_readwrite("state", &PathlineGroup::state, "Which fire bake (state) of the graph.");
  g.def_readwrite("step", &PathlineGroup::step, "k: node step at which the group was seeded.");
  g.def_readonly("layout", &PathlineGroup::layout, "|Ω|, L and Δt_n.");
  // Read-only NumPy views: (P, 3) start, (P, L, 3) velocity, (P, L) density and temperature.
  auto array = [&g](const char* name, const float* (*data)(const PathlineGroup&), int components,
                    bool perSample, const char* doc) {
    g.def_property_readonly(
        name,
        [=](py::object self) {
          const auto& p = self.cast<const PathlineGroup&>();
          std::vector<py::ssize_t> shape{p.layout.particles};
          if (perSample) shape.push_back(p.layout.samples);
          if (components > 1) shape.push_back(components);
          return view(self, data(p), shape);
        },
        doc);
  };
  array("start", [](const PathlineGroup& p) { return &p.start[0].x; }, 3, false,
        "x_0 per particle, (P, 3) float32 view, world metres.");
  array("velocity", [](const PathlineGroup& p) { return &p.velocity[0].x; }, 3, true,
        "u per sample, (P, L, 3) float32 view, m/s.");
  array("density", [](const PathlineGroup& p) { return p.density.data(); }, 1, true,
        "Density (smoke + soot) per sample, (P, L) float32 view.");
  array("temperature", [](const PathlineGroup& p) { return p.temperature.data(); }, 1, true,
        "Temperature per sample, (P, L) float32 view.");
}

}  // namespace plume::bindings
