// SmokeParams::linearVelocity (Fast Velocity) carries the velocity with trilinear BFECC and the
// scalars with monotonic cubic BFECC (SmokeSolver::advect()). On a smooth field trilinear BFECC
// must keep nearly what cubic BFECC (the scheme before) keeps, and far more than the trilinear
// MacCormack Mantaflow carries its velocity with: a Gaussian carried once around a rigid
// rotation, with no new extrema.
#include "solver/advection.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace plume {
namespace {

constexpr float kPi = 3.14159265358979f;

/// Rigid rotation about the z axis through cell coordinates `centre`, ω rad per unit time, on the
/// faces (u(i,j,k) sits at cell coordinates (i - ½, j, k), v(i,j,k) at (i, j - ½, k)).
MacGrid3 rotation(glm::ivec3 n, glm::vec2 centre, float omega) {
  MacGrid3 v(n);
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i <= n.x; ++i) v.u()(i, j, k) = -omega * (float(j) - centre.y);
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j <= n.y; ++j)
      for (int i = 0; i < n.x; ++i) v.v()(i, j, k) = omega * (float(i) - centre.x);
  return v;
}

/// A Gaussian blob of peak 1 and σ cells around cell coordinates c.
ScalarGrid blob(glm::ivec3 n, glm::vec3 c, float sigma) {
  ScalarGrid g(n);
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const glm::vec3 d = glm::vec3(i, j, k) - c;
        g(i, j, k) = std::exp(-glm::dot(d, d) / (2.f * sigma * sigma));
      }
  return g;
}

struct Result {
  float lo, hi;    ///< smallest and largest value after the revolution
  double error;    ///< Σ |φ - φ₀| / Σ φ₀ (the exact solution is the start)
};

/// One revolution of `start` in `steps` steps of `scheme` with `interpolation` (midpoint traces).
Result revolve(const ScalarGrid& start, Advection scheme, Interpolation interpolation, int steps) {
  const glm::ivec3 n = start.size();
  const float dt = 1.f, omega = 2.f * kPi / float(steps);
  const MacGrid3 velocity = rotation(n, {0.5f * float(n.x - 1), 0.5f * float(n.y - 1)}, omega);
  Advector advector;
  advector.reserve(start.count(), 1, scheme);
  advector.trace(velocity, n, kCellOffset, dt, 1.f, scheme, nullptr, Trace::Midpoint);
  ScalarGrid phi = start, next;
  for (int s = 0; s < steps; ++s) {
    advector.advect(phi, next, interpolation, nullptr, 0.f);
    std::swap(phi.values(), next.values());
  }
  Result r{1e9f, -1e9f, 0.0};
  double total = 0.0;
  for (std::size_t c = 0; c < phi.count(); ++c) {
    r.lo = std::min(r.lo, phi[c]);
    r.hi = std::max(r.hi, phi[c]);
    r.error += std::fabs(double(phi[c]) - double(start[c]));
    total += start[c];
  }
  r.error /= total;
  return r;
}

TEST(AdvectionVelocity, TrilinearBfeccKeepsASmoothFieldLikeCubicBfecc) {
  // 40 steps a revolution move the blob's centre 1.9 cells a step (12 cells from the axis), a
  // typical step of the solver's default sub-steps (CFL number up to 4). σ = 2.5 cells: a
  // velocity feature resolved by about five cells, as the buoyant plume's are.
  constexpr int kSteps = 40;
  const ScalarGrid start = blob({40, 40, 12}, {31.5f, 19.5f, 5.5f}, 2.5f);
  const Result cubic = revolve(start, Advection::Bfecc, Interpolation::MonotonicCubic, kSteps);
  const Result linear = revolve(start, Advection::Bfecc, Interpolation::Linear, kSteps);
  const Result mantaflow = revolve(start, Advection::MacCormack, Interpolation::Linear, kSteps);
  // No new extrema: the clamp keeps every value in the start's range [0, 1].
  EXPECT_GE(linear.lo, 0.f);
  EXPECT_LE(linear.hi, 1.f);
  // Measured: L1 error 0.115 against cubic's 0.098 and the trilinear MacCormack's 0.369; peak
  // 0.859 against 0.907 and 0.702. Bounds: the error within 25% of cubic BFECC's, under half
  // of trilinear MacCormack's; the peak within 0.06 of cubic BFECC's (6% of the start's).
  EXPECT_LE(linear.error, 1.25 * cubic.error) << "cubic BFECC " << cubic.error;
  EXPECT_LE(linear.error, 0.5 * mantaflow.error) << "trilinear MacCormack " << mantaflow.error;
  EXPECT_GE(linear.hi, cubic.hi - 0.06f) << "cubic BFECC peak " << cubic.hi;
  EXPECT_GT(linear.hi, mantaflow.hi) << "trilinear MacCormack peak " << mantaflow.hi;
}

}  // namespace
}  // namespace plume
