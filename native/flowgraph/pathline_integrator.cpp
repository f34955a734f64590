#include "flowgraph/pathline_integrator.h"

#include "core/sample_points.h"

#include <cmath>

namespace plume {
namespace {

/// Trilinear sample of one face component at index-space position p, from the start and end
/// grids blended in time with the same weights (one split serves both grids).
inline float blendedLinear(const ScalarGrid& a, const ScalarGrid& b, glm::vec3 p, float theta) {
  const glm::ivec3 n = a.size();
  int i, j, k;
  float tx, ty, tz;
  splitCoordinate(p.x, n.x, i, tx);
  splitCoordinate(p.y, n.y, j, ty);
  splitCoordinate(p.z, n.z, k, tz);
  // After splitCoordinate() the +1 neighbour exists on every axis longer than one sample.
  const std::ptrdiff_t dx = n.x > 1 ? 1 : 0;
  const std::ptrdiff_t dy = n.y > 1 ? a.strideY() : 0;
  const std::ptrdiff_t dz = n.z > 1 ? a.strideZ() : 0;
  const std::size_t base = a.index(i, j, k);
  const float* qa = a.data() + base;
  const float* qb = b.data() + base;
  const float s = 1.f - theta;
  float c[8];
  const std::ptrdiff_t off[8] = {0, dx, dy, dy + dx, dz, dz + dx, dz + dy, dz + dy + dx};
  if (theta == 0.f) {
    for (int m = 0; m < 8; ++m) c[m] = qa[off[m]];
  } else if (theta == 1.f) {
    for (int m = 0; m < 8; ++m) c[m] = qb[off[m]];
  } else {
    for (int m = 0; m < 8; ++m) c[m] = s * qa[off[m]] + theta * qb[off[m]];
  }
  const float c00 = c[0] + tx * (c[1] - c[0]);
  const float c10 = c[2] + tx * (c[3] - c[2]);
  const float c01 = c[4] + tx * (c[5] - c[4]);
  const float c11 = c[6] + tx * (c[7] - c[6]);
  const float c0 = c00 + ty * (c10 - c00);
  const float c1 = c01 + ty * (c11 - c01);
  return c0 + tz * (c1 - c0);
}

}  // namespace

glm::vec3 SubstepVelocity::at(glm::vec3 x, float theta) const {
  // Cell coordinates: cell (i,j,k)'s centre is (i,j,k); u(i,j,k) sits at (i - 1/2, j, k).
  const glm::vec3 c = (x - mOrigin) * mInvCellSize - glm::vec3(0.5f);
  return {blendedLinear(mStart.u(), mEnd.u(), c + glm::vec3(0.5f, 0.f, 0.f), theta),
          blendedLinear(mStart.v(), mEnd.v(), c + glm::vec3(0.f, 0.5f, 0.f), theta),
          blendedLinear(mStart.w(), mEnd.w(), c + glm::vec3(0.f, 0.f, 0.5f), theta)};
}

glm::vec3 integrateRk4(const SubstepVelocity& u, glm::vec3 x, float thetaA, float thetaB,
                       float dt, int steps, const glm::vec3* k1) {
  const float dTheta = (thetaB - thetaA) / float(steps);
  const float h = dTheta * dt;  // seconds per RK4 step
  for (int s = 0; s < steps; ++s) {
    const float t0 = thetaA + float(s) * dTheta;
    const float tm = t0 + 0.5f * dTheta;
    const float t1 = s + 1 == steps ? thetaB : t0 + dTheta;
    const glm::vec3 a = (s == 0 && k1) ? *k1 : u.at(x, t0);
    const glm::vec3 b = u.at(x + 0.5f * h * a, tm);
    const glm::vec3 c = u.at(x + 0.5f * h * b, tm);
    const glm::vec3 d = u.at(x + h * c, t1);
    x += (h / 6.f) * (a + 2.f * (b + c) + d);
  }
  return x;
}

glm::vec3 advancePathline(const SubstepVelocity& u, glm::vec3 x, float thetaA, float thetaB,
                          float dt, float cellSize) {
  const glm::vec3 k1 = u.at(x, thetaA);
  const float cells = glm::length(k1) * (thetaB - thetaA) * dt / cellSize;
  // A NaN speed (broken field) compares false and takes one step.
  int steps = 1;
  if (cells > 1.f) steps = cells >= float(kMaxRk4Steps) ? kMaxRk4Steps : int(std::ceil(cells));
  return integrateRk4(u, x, thetaA, thetaB, dt, steps, &k1);
}

}  // namespace plume
