/// \file bind_io.cpp
/// Reading back the per-frame VDB files (tests, previews): grid names and one grid as a dense
/// NumPy box.

#include "bindings/bindings.h"
#include "bindings/convert.h"

#include "io/vdb_frame.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstring>

namespace py = pybind11;

namespace plume::bindings {

void bindIo(py::module_& m) {
  m.def(
      "vdb_grid_names",
      [](const py::object& path) { return withPath(path, vdbGridNames); },
      py::arg("path"), "Names of the grids in a VDB file (RuntimeError if it cannot be read).");
  m.def(
      "read_vdb_grid",
      [](const py::object& path, const std::string& name) {
        const DenseGrid g = withPath(path, [&](const std::string& p) { return readVdbGrid(p, name); });
        const py::ssize_t c = g.components;
        std::vector<py::ssize_t> shape{g.size.x, g.size.y, g.size.z};
        // x fastest with components interleaved: Fortran order over (i, j, k), component last
        // in memory order but first in stride.
        const py::ssize_t f = sizeof(float);
        std::vector<py::ssize_t> strides{c * f, c * f * g.size.x, c * f * g.size.x * g.size.y};
        if (c > 1) {
          shape.push_back(c);
          strides.push_back(f);
        }
        py::array_t<float> values(shape, strides);
        if (!g.values.empty())
          std::memcpy(values.mutable_data(), g.values.data(), g.values.size() * sizeof(float));
        py::dict d;
        d["values"] = values;
        d["min"] = vec3Tuple(g.min);
        d["voxel_size"] = g.voxelSize;
        d["world_of_voxel_zero"] = vec3Tuple(g.worldOfVoxelZero);
        return d;
      },
      py::arg("path"), py::arg("name"),
      "Reads one float or vec3 grid as dict(values=float32 array (sx, sy, sz) or (sx, sy, sz, 3) "
      "indexed [i, j, k], min=(i, j, k) index of values[0, 0, 0], voxel_size, "
      "world_of_voxel_zero=(x, y, z) centre of voxel (0, 0, 0)). RuntimeError if missing.");
}

}  // namespace plume::bindings
