#pragma once
/// \file multigrid_level.h
/// One level of the MGPCG hierarchy (pressure.cpp): padded storage with one ghost cell on each
/// side, so the inner loops of the smoother and the residual need no bounds checks.

#include <glm/glm.hpp>

#include <cstddef>
#include <vector>

namespace plume {
namespace detail {

/// One level of the hierarchy (padded storage, see the file comment).
struct Level {
  glm::ivec3 n{0};
  std::ptrdiff_t sy = 0, sz = 0;  ///< padded strides
  std::vector<float> diag;        ///< fluid neighbours + air neighbours; 0 on solid and ghosts
  std::vector<float> wInv;        ///< ω / diag on fluid cells, else 0
  std::vector<float> b, x, t;     ///< rhs, solution, scratch (level 0: CG's r, z and q)
  std::vector<float> rows;        ///< residual rows for the restriction, one per coarse slice

  std::size_t at(int i, int j, int k) const {
    return std::size_t((i + 1) + sy * (j + 1) + sz * (k + 1));
  }
  std::size_t padded() const { return std::size_t(n.x + 2) * (n.y + 2) * (n.z + 2); }
};

}  // namespace detail
}  // namespace plume
