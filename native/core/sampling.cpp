#include "core/sampling.h"

#include <cmath>

namespace plume {
namespace {

/// Integer cell and fraction of a coordinate clamped into [0, n-1].
inline void split(float x, int n, int& i, float& t) {
  const float hi = float(n - 1);
  x = x < 0.f ? 0.f : (x > hi ? hi : x);
  i = int(x);
  if (i >= n - 1) i = n > 1 ? n - 2 : 0;
  t = x - float(i);
}

}  // namespace

float sampleLinear(const ScalarGrid& g, glm::vec3 p) {
  const glm::ivec3 n = g.size();
  int i, j, k;
  float tx, ty, tz;
  split(p.x, n.x, i, tx);
  split(p.y, n.y, j, ty);
  split(p.z, n.z, k, tz);
  const int i1 = n.x > 1 ? i + 1 : i, j1 = n.y > 1 ? j + 1 : j, k1 = n.z > 1 ? k + 1 : k;
  const float c00 = g(i, j, k) + tx * (g(i1, j, k) - g(i, j, k));
  const float c10 = g(i, j1, k) + tx * (g(i1, j1, k) - g(i, j1, k));
  const float c01 = g(i, j, k1) + tx * (g(i1, j, k1) - g(i, j, k1));
  const float c11 = g(i, j1, k1) + tx * (g(i1, j1, k1) - g(i, j1, k1));
  const float c0 = c00 + ty * (c10 - c00);
  const float c1 = c01 + ty * (c11 - c01);
  return c0 + tz * (c1 - c0);
}

float monotonicCubic1D(float f0, float f1, float f2, float f3, float t) {
  const float delta = f2 - f1;
  float d1 = 0.5f * (f2 - f0);
  float d2 = 0.5f * (f3 - f1);
  if (delta == 0.f) {
    d1 = d2 = 0.f;  // flat interval: Fedkiw sets both slopes to zero
  } else {
    // Slopes must share the sign of Δ (Fedkiw 2001); |d| <= 3|Δ| keeps the Hermite cubic monotone.
    const float lim = 3.f * std::fabs(delta);
    if (d1 * delta <= 0.f) d1 = 0.f;
    else if (std::fabs(d1) > lim) d1 = std::copysign(lim, delta);
    if (d2 * delta <= 0.f) d2 = 0.f;
    else if (std::fabs(d2) > lim) d2 = std::copysign(lim, delta);
  }
  const float t2 = t * t, t3 = t2 * t;
  // Fedkiw eq. 12: f(t) = a3 t^3 + a2 t^2 + a1 t + a0.
  const float a3 = d1 + d2 - 2.f * delta;
  const float a2 = 3.f * delta - 2.f * d1 - d2;
  const float value = a3 * t3 + a2 * t2 + d1 * t + f1;
  // Exact arithmetic keeps the value between f1 and f2; the clamp also rules out rounding.
  const float lo = f1 < f2 ? f1 : f2, hi = f1 < f2 ? f2 : f1;
  return value < lo ? lo : (value > hi ? hi : value);
}

float sampleMonotonicCubic(const ScalarGrid& g, glm::vec3 p) {
  const glm::ivec3 n = g.size();
  int i, j, k;
  float tx, ty, tz;
  split(p.x, n.x, i, tx);
  split(p.y, n.y, j, ty);
  split(p.z, n.z, k, tz);
  float zs[4];
  for (int c = 0; c < 4; ++c) {
    float ys[4];
    for (int b = 0; b < 4; ++b) {
      const int jj = j - 1 + b, kk = k - 1 + c;
      ys[b] = monotonicCubic1D(g.clampedAt(i - 1, jj, kk), g.clampedAt(i, jj, kk),
                               g.clampedAt(i + 1, jj, kk), g.clampedAt(i + 2, jj, kk), tx);
    }
    zs[c] = monotonicCubic1D(ys[0], ys[1], ys[2], ys[3], ty);
  }
  return monotonicCubic1D(zs[0], zs[1], zs[2], zs[3], tz);
}

void sampleRange(const ScalarGrid& g, glm::vec3 p, float& lo, float& hi) {
  const glm::ivec3 n = g.size();
  int i, j, k;
  float tx, ty, tz;
  split(p.x, n.x, i, tx);
  split(p.y, n.y, j, ty);
  split(p.z, n.z, k, tz);
  lo = hi = g(i, j, k);
  for (int c = 0; c < 2; ++c)
    for (int b = 0; b < 2; ++b)
      for (int a = 0; a < 2; ++a) {
        const float f = g.clampedAt(i + a, j + b, k + c);
        lo = f < lo ? f : lo;
        hi = f > hi ? f : hi;
      }
}

glm::vec3 sampleVelocity(const MacGrid3& vel, glm::vec3 p) {
  // u(i,j,k) sits at cell coordinates (i - 1/2, j, k): shift p into each component's index space.
  return {sampleLinear(vel.u(), p + glm::vec3(0.5f, 0.f, 0.f)),
          sampleLinear(vel.v(), p + glm::vec3(0.f, 0.5f, 0.f)),
          sampleLinear(vel.w(), p + glm::vec3(0.f, 0.f, 0.5f))};
}

glm::vec3 sampleVelocity(const MacGrid3& vel, glm::vec3 p, Interpolation scheme) {
  return {sample(vel.u(), p + glm::vec3(0.5f, 0.f, 0.f), scheme),
          sample(vel.v(), p + glm::vec3(0.f, 0.5f, 0.f), scheme),
          sample(vel.w(), p + glm::vec3(0.f, 0.f, 0.5f), scheme)};
}

}  // namespace plume
