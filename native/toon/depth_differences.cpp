/// \file depth_differences.cpp
/// Row-parallel depth-differences filter ([Cartoon Smoke] §2.2). Every horizontal difference is
/// shared by the two pixels beside it, and every vertical one by the two rows beside it, so each
/// is computed once per block of rows.

#include "toon/depth_differences.h"

#include "core/parallel.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace plume {
namespace {

/// Rows per parallel task (a 1080-row image gives 34 tasks).
constexpr int kRowsPerTask = 32;

std::string number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// Whether v is a power of two whose reciprocal is a normal float: then a / v and a * (1 / v)
/// are the same real number, so they round to the same float.
bool exactReciprocal(float v) {
  int e = 0;
  return std::frexp(v, &e) == 0.5f && std::isnormal(1.f / v);
}

/// One difference test: |b - a| / d > γ, with `inv` = 1 / d when kScale (exact, see above).
template <bool kScale>
struct Edge {
  float d, inv, gamma;
  std::uint8_t operator()(float a, float b) const {
    const float diff = std::abs(b - a);
    return std::uint8_t((kScale ? diff * inv : diff / d) > gamma);
  }
};

/// Vertical edge flags between rows a and b: e[i] = test(a[i], b[i]).
template <typename E>
void verticalEdges(const E& edge, const float* a, const float* b, int w, std::uint8_t* e) {
  for (int i = 0; i < w; ++i) e[i] = edge(a[i], b[i]);
}

template <typename EX, typename EY>
void filterRows(const float* depth, int w, int h, int j0, int j1, const EX& ex, const EY& ey,
                const DepthDifferenceParams& p, std::uint8_t* out) {
  const std::size_t n = std::size_t(w);
  // horizontal[i]: the edge between pixels i-1 and i (0 beyond both borders); up / down: the
  // edges to the rows above and below (0 beyond the image).
  std::vector<std::uint8_t> horizontal(n + 1, 0), up(n, 0), down(n, 0);
  if (j0 > 0) verticalEdges(ey, depth + std::size_t(j0 - 1) * n, depth + std::size_t(j0) * n, w, up.data());
  const float far = p.far;
  for (int j = j0; j < j1; ++j) {
    const float* r = depth + std::size_t(j) * n;
    std::uint8_t* o = out + std::size_t(j) * n;
    std::uint8_t* hz = horizontal.data();
    for (int i = 1; i < w; ++i) hz[i] = ex(r[i - 1], r[i]);
    if (j + 1 < h)
      verticalEdges(ey, r, r + n, w, down.data());
    else
      std::fill(down.begin(), down.end(), std::uint8_t(0));
    const std::uint8_t* u = up.data();
    const std::uint8_t* d = down.data();
    // One pass: any of the four edges, never on a background pixel when it is ignored.
    if (p.ignoreBackground)
      for (int i = 0; i < w; ++i) o[i] = (hz[i] | hz[i + 1] | u[i] | d[i]) & std::uint8_t(r[i] < far);
    else
      for (int i = 0; i < w; ++i) o[i] = hz[i] | hz[i + 1] | u[i] | d[i];
    std::swap(up, down);  // this row's lower edges are the next row's upper edges
  }
}

template <typename EX, typename EY>
void filterImage(const float* depth, int w, int h, const EX& ex, const EY& ey,
                 const DepthDifferenceParams& p, std::uint8_t* out) {
  parallelFor(0, (h + kRowsPerTask - 1) / kRowsPerTask, [&](int t) {
    filterRows(depth, w, h, t * kRowsPerTask, std::min(h, (t + 1) * kRowsPerTask), ex, ey, p, out);
  });
}

template <typename EX>
void dispatchY(const float* depth, int w, int h, const EX& ex, const DepthDifferenceParams& p,
               std::uint8_t* out) {
  if (exactReciprocal(p.dy))
    filterImage(depth, w, h, ex, Edge<true>{p.dy, 1.f / p.dy, p.gamma}, p, out);
  else
    filterImage(depth, w, h, ex, Edge<false>{p.dy, 1.f, p.gamma}, p, out);
}

}  // namespace

void DepthDifferenceParams::validate() const {
  if (!(gamma >= 0.f) || !std::isfinite(gamma))
    throw std::invalid_argument("gamma must be a finite number >= 0 (got " + number(gamma) + ")");
  if (!(dx > 0.f) || !std::isfinite(dx))
    throw std::invalid_argument("dx must be a finite number > 0 (got " + number(dx) + ")");
  if (!(dy > 0.f) || !std::isfinite(dy))
    throw std::invalid_argument("dy must be a finite number > 0 (got " + number(dy) + ")");
  if (std::isnan(far)) throw std::invalid_argument("far must be a number (got NaN)");
}

void depthDifferences(const float* depth, int width, int height,
                      const DepthDifferenceParams& params, std::uint8_t* out) {
  params.validate();
  if (width < 0 || height < 0)
    throw std::invalid_argument("depth image size must be >= 0 (got " + std::to_string(width) +
                                " x " + std::to_string(height) + ")");
  if (width == 0 || height == 0) return;
  if (exactReciprocal(params.dx))
    dispatchY(depth, width, height, Edge<true>{params.dx, 1.f / params.dx, params.gamma}, params, out);
  else
    dispatchY(depth, width, height, Edge<false>{params.dx, 1.f, params.gamma}, params, out);
}

}  // namespace plume
