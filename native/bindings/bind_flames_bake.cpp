/// \file bind_flames_bake.cpp
/// What the add-on's flame bake needs beyond the flame core's own bindings: obstacles voxelized
/// into a signed-distance grid ([Structural Flames] §6.1) for GridSdf.

#include "bindings/bindings.h"
#include "bindings/convert.h"

#include "flames/mesh_sdf.h"

#include <string>

namespace py = pybind11;

namespace plume::bindings {

void bindFlamesBake(py::module_& m) {
  m.def(
      "mesh_signed_distance",
      [](const FloatArrayC& vertices, const Int64ArrayC& triangles, double voxelSize, double padding, const std::string& name) {
        if (vertices.ndim() != 2 || vertices.shape(1) != 3)
          throw py::value_error("vertices of obstacle '" + name + "' must have shape (N, 3)");
        if (triangles.ndim() != 2 || triangles.shape(1) != 3)
          throw py::value_error("triangles of obstacle '" + name + "' must have shape (M, 3)");
        const std::vector<glm::vec3> v = pointsArg(vertices, "vertices");
        std::vector<glm::ivec3> t(std::size_t(triangles.shape(0)));
        const long long* tp = triangles.data();
        for (std::size_t n = 0; n < t.size() * 3; ++n) t[n / 3][int(n % 3)] = int(tp[n]);
        MeshSdfGrid g;
        {
          py::gil_scoped_release release;
          g = meshSignedDistance(v, t, voxelSize, padding, name);
        }
        py::dict d;
        d["values"] = gridArray(g.values);
        d["cell_size"] = g.cellSize;
        d["origin"] = vec3Tuple(g.origin);
        return d;
      },
      py::arg("vertices"), py::arg("triangles"), py::arg("voxel_size"), py::arg("padding") = 0.0,
      py::arg("name") = std::string("obstacle"),
      "§6.1: signed distance (m, < 0 inside) of a closed mesh (world-space vertices (N, 3), "
      "triangles (M, 3)) on cells of voxel_size over its bounding box grown by padding: "
      "dict(values=float32 (nx, ny, nz) indexed [i, j, k], cell_size, origin) with cell (i, j, k) "
      "centred at origin + (i + 0.5, j + 0.5, k + 0.5) * cell_size. ValueError naming the "
      "obstacle for an open or empty mesh or too many voxels.");
}

}  // namespace plume::bindings
