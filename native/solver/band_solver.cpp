#include "solver/band_solver.h"

#include <algorithm>
#include <cmath>

namespace plume {
namespace detail {

void BandSolver::build(const Level& L) {
  int ax[3] = {0, 1, 2};  // fastest, middle, slowest = the longest axis
  // Equal lengths keep their axis order: the same numbering with every standard library.
  std::sort(ax, ax + 3, [&](int a, int b) { return L.n[a] != L.n[b] ? L.n[a] < L.n[b] : a < b; });
  std::vector<int> number(L.padded(), -1);
  cells.clear();
  glm::ivec3 c;
  for (c[ax[2]] = 0; c[ax[2]] < L.n[ax[2]]; ++c[ax[2]])
    for (c[ax[1]] = 0; c[ax[1]] < L.n[ax[1]]; ++c[ax[1]])
      for (c[ax[0]] = 0; c[ax[0]] < L.n[ax[0]]; ++c[ax[0]]) {
        const std::size_t o = L.at(c.x, c.y, c.z);
        if (L.diag[o] > 0.f) {
          number[o] = int(cells.size());
          cells.push_back(o);
        }
      }
  n = int(cells.size());
  const std::ptrdiff_t off[3] = {1, L.sy, L.sz};
  w = 0;
  for (int i = 0; i < n; ++i)
    for (std::ptrdiff_t s : off)
      if (number[cells[i] + s] >= 0) w = std::max(w, number[cells[i] + s] - i);
  l.assign(std::size_t(n) * (w + 1), 0.0);
  y.assign(std::size_t(n), 0.0);
  for (int i = 0; i < n; ++i) {
    at(i, i) = L.diag[cells[i]];
    for (std::ptrdiff_t s : off)
      if (number[cells[i] - s] >= 0) at(i, number[cells[i] - s]) = -1.0;
  }
  for (int i = 0; i < n; ++i) {
    const int j0 = std::max(0, i - w);
    for (int j = j0; j <= i; ++j) {
      double s = at(i, j);
      for (int k = j0; k < j; ++k) s -= at(i, k) * at(j, k);
      if (j < i)
        at(i, j) = at(j, j) > 0.0 ? s / at(j, j) : 0.0;
      else
        at(i, i) = s > 1e-10 * L.diag[cells[i]] ? std::sqrt(s) : 0.0;
    }
  }
}

void BandSolver::solve(Level& L) {
  for (int i = 0; i < n; ++i) {
    double s = L.b[cells[i]];
    for (int k = std::max(0, i - w); k < i; ++k) s -= at(i, k) * y[k];
    y[i] = at(i, i) > 0.0 ? s / at(i, i) : 0.0;
  }
  for (int i = n - 1; i >= 0; --i) {
    double s = y[i];
    for (int k = i + 1; k <= std::min(n - 1, i + w); ++k) s -= at(k, i) * y[k];
    y[i] = at(i, i) > 0.0 ? s / at(i, i) : 0.0;
  }
  for (int i = 0; i < n; ++i) L.x[cells[i]] = float(y[i]);
}

}  // namespace detail
}  // namespace plume
