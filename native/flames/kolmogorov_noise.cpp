/// \file kolmogorov_noise.cpp
/// Spectral synthesis of the Kolmogorov tile (a small radix-2 FFT) and its trilinear lookup.

#include "flames/kolmogorov_noise.h"

#include "core/format.h"
#include "core/rng.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Iterative radix-2 FFT of `n` values `stride` apart.
void fft1d(std::complex<double>* a, int n, int stride, bool inverse) {
  for (int i = 1, j = 0; i < n; ++i) {
    int bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(a[i * stride], a[j * stride]);
  }
  for (int len = 2; len <= n; len <<= 1) {
    const double angle = 2.0 * kPi / len * (inverse ? 1.0 : -1.0);
    const std::complex<double> wl(std::cos(angle), std::sin(angle));
    for (int i = 0; i < n; i += len) {
      std::complex<double> w(1.0);
      for (int k = 0; k < len / 2; ++k) {
        const std::complex<double> u = a[(i + k) * stride], v = a[(i + k + len / 2) * stride] * w;
        a[(i + k) * stride] = u + v;
        a[(i + k + len / 2) * stride] = u - v;
        w *= wl;
      }
    }
  }
}

double gaussian(Rng& rng) {
  // Box–Muller; 1 - u keeps the logarithm finite.
  return std::sqrt(-2.0 * std::log(1.0 - rng.uniform())) * std::cos(2.0 * kPi * rng.uniform());
}

}  // namespace

void fft3d(std::vector<std::complex<double>>& data, int n, bool inverse) {
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j) fft1d(&data[std::size_t((k * n + j) * n)], n, 1, inverse);
  for (int k = 0; k < n; ++k)
    for (int i = 0; i < n; ++i) fft1d(&data[std::size_t(k * n * n + i)], n, n, inverse);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) fft1d(&data[std::size_t(j * n + i)], n, n * n, inverse);
}

void KolmogorovParams::validate() const {
  auto bound = [](double v) { return formatNumber(v); };
  if (!(amplitude >= 0.0 && amplitude <= kMaxKolmogorovAmplitude))
    throw std::invalid_argument("kolmogorov_amplitude must be in [0, " + bound(kMaxKolmogorovAmplitude) + "] m (got " +
                                bound(amplitude) + ")");
  if (!(scale > 0.0 && scale <= kMaxKolmogorovScale))
    throw std::invalid_argument("kolmogorov_scale (Lambda) must be in (0, " + bound(kMaxKolmogorovScale) + "] m (got " +
                                bound(scale) + ")");
  for (int a = 0; a < 3; ++a)
    if (!(std::abs(drift[a]) <= kMaxKolmogorovDrift))
      throw std::invalid_argument(std::string("kolmogorov_drift (c) ") + "xyz"[a] + " must be in [-" +
                                  bound(kMaxKolmogorovDrift) + ", " + bound(kMaxKolmogorovDrift) + "] m/s (got " +
                                  bound(drift[a]) + ")");
  if (!(frequency >= 0.0 && frequency <= kMaxKolmogorovFrequency))
    throw std::invalid_argument("kolmogorov_frequency (nu) must be in [0, " + bound(kMaxKolmogorovFrequency) +
                                "] Hz (got " + bound(frequency) + ")");
  if (resolution < 8 || resolution > 128 || (resolution & (resolution - 1)) != 0)
    throw std::invalid_argument("kolmogorov_resolution must be a power of two in [8, 128] (got " +
                                std::to_string(resolution) + ")");
}

KolmogorovNoise::KolmogorovNoise(const KolmogorovParams& params, std::uint64_t seed) : mParams(params) {
  params.validate();
  const int n = mN = params.resolution;
  const std::size_t count = std::size_t(n) * n * n;
  std::vector<std::complex<double>> c[3];
  for (auto& v : c) v.assign(count, 0.0);
  Rng rng(seed, /*stream=*/0x4B6F6C6D);
  auto wave = [n](int i) { return i < n / 2 ? i : i - n; };
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const std::size_t m = std::size_t((k * n + j) * n + i);
        glm::dvec3 a[2];  // real and imaginary parts of the 3 components
        for (auto& part : a) part = {gaussian(rng), gaussian(rng), gaussian(rng)};
        const glm::dvec3 kv(wave(i), wave(j), wave(k));
        const double kk = glm::length(kv);
        if (kk < 1.0 || kk > 0.5 * n) continue;
        const double amp = std::pow(kk, -11.0 / 6.0);
        for (auto& part : a) part = amp * (part - kv * (glm::dot(kv, part) / (kk * kk)));
        for (int d = 0; d < 3; ++d) c[d][m] = {a[0][d], a[1][d]};
      }
  for (auto& v : c) fft3d(v, n, /*inverse=*/true);
  double sum2 = 0.0;
  for (std::size_t m = 0; m < count; ++m)
    for (auto& v : c) sum2 += v[m].real() * v[m].real();
  const double norm = sum2 > 0.0 ? 1.0 / std::sqrt(sum2 / double(count)) : 0.0;
  mTile.resize(count);
  for (std::size_t m = 0; m < count; ++m)
    mTile[m] = glm::vec3(float(c[0][m].real() * norm), float(c[1][m].real() * norm), float(c[2][m].real() * norm));
}

glm::dvec3 KolmogorovNoise::tile(const glm::dvec3& u) const {
  const int n = mN;
  const double fx = std::floor(u.x), fy = std::floor(u.y), fz = std::floor(u.z);
  const glm::dvec3 f(u.x - fx, u.y - fy, u.z - fz);
  auto wrap = [n](double v) { return int(static_cast<long long>(v) & (n - 1)); };  // n: a power of two
  const int i0 = wrap(fx), j0 = wrap(fy), k0 = wrap(fz);
  const int i1 = (i0 + 1) & (n - 1), j1 = (j0 + 1) & (n - 1), k1 = (k0 + 1) & (n - 1);
  auto at = [&](int i, int j, int k) { return glm::dvec3(mTile[std::size_t((k * n + j) * n + i)]); };
  const glm::dvec3 x00 = glm::mix(at(i0, j0, k0), at(i1, j0, k0), f.x);
  const glm::dvec3 x10 = glm::mix(at(i0, j1, k0), at(i1, j1, k0), f.x);
  const glm::dvec3 x01 = glm::mix(at(i0, j0, k1), at(i1, j0, k1), f.x);
  const glm::dvec3 x11 = glm::mix(at(i0, j1, k1), at(i1, j1, k1), f.x);
  return glm::mix(glm::mix(x00, x10, f.y), glm::mix(x01, x11, f.y), f.z);
}

glm::dvec2 KolmogorovNoise::blend(double t) const {
  const double phi = 2.0 * kPi * mParams.frequency * t;
  return {std::cos(phi), std::sin(phi)};
}

glm::dvec3 KolmogorovNoise::displacement(const glm::dvec3& x, double t) const {
  return displacement(x, t, blend(t));
}

glm::dvec3 KolmogorovNoise::displacement(const glm::dvec3& x, double t, glm::dvec2 w) const {
  if (mParams.amplitude <= 0.0) return glm::dvec3(0.0);
  // w.x T(u) + w.y T(u + N/2), both trilinear with the same weights (N/2 is a whole number of
  // cells): blend the two tiles' corners, then interpolate once. Single precision, as the tile.
  const glm::dvec3 u = (x - mParams.drift * t) * (double(mN) / mParams.scale);
  const glm::dvec3 floorU = glm::floor(u);
  const glm::vec3 f(u - floorU);
  const int mask = mN - 1, half = mN / 2;  // N is a power of two: wrapping is a mask
  const int i0 = int(static_cast<long long>(floorU.x) & mask), j0 = int(static_cast<long long>(floorU.y) & mask),
            k0 = int(static_cast<long long>(floorU.z) & mask);
  const int is[4] = {i0, (i0 + 1) & mask, (i0 + half) & mask, (i0 + half + 1) & mask};
  const int js[4] = {j0, (j0 + 1) & mask, (j0 + half) & mask, (j0 + half + 1) & mask};
  const int ks[4] = {k0, (k0 + 1) & mask, (k0 + half) & mask, (k0 + half + 1) & mask};
  const float wa = float(w.x), wb = float(w.y);
  glm::vec3 corner[8];
  for (int c = 0; c < 8; ++c) {
    const int a = c & 1, b = (c >> 1) & 1, e = c >> 2;
    const glm::vec3& p = mTile[std::size_t((ks[e] * mN + js[b]) * mN + is[a])];
    const glm::vec3& q = mTile[std::size_t((ks[e + 2] * mN + js[b + 2]) * mN + is[a + 2])];
    corner[c] = wa * p + wb * q;
  }
  const glm::vec3 x0 = glm::mix(glm::mix(corner[0], corner[1], f.x), glm::mix(corner[2], corner[3], f.x), f.y);
  const glm::vec3 x1 = glm::mix(glm::mix(corner[4], corner[5], f.x), glm::mix(corner[6], corner[7], f.x), f.y);
  return mParams.amplitude * glm::dvec3(glm::mix(x0, x1, f.z));
}

KolmogorovFrame::KolmogorovFrame(const KolmogorovNoise& noise, double t) : mNoise(noise), mTime(t) {
  if (noise.mParams.amplitude <= 0.0) return;
  const glm::dvec2 w = noise.blend(t);
  const float wa = float(w.x), wb = float(w.y);
  const int n = noise.mN, mask = n - 1, half = n / 2;
  mBlend.resize(noise.mTile.size());
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j) {
      const glm::vec3* p = &noise.mTile[std::size_t((k * n + j) * n)];
      const glm::vec3* q = &noise.mTile[std::size_t((((k + half) & mask) * n + ((j + half) & mask)) * n)];
      glm::vec3* out = &mBlend[std::size_t((k * n + j) * n)];
      for (int i = 0; i < n; ++i) out[i] = wa * p[i] + wb * q[(i + half) & mask];
    }
}

glm::dvec3 KolmogorovFrame::displacement(const glm::dvec3& x) const {
  const KolmogorovParams& params = mNoise.mParams;
  if (params.amplitude <= 0.0) return glm::dvec3(0.0);
  const int n = mNoise.mN, mask = n - 1;
  const glm::dvec3 u = (x - params.drift * mTime) * (double(n) / params.scale);
  const glm::dvec3 floorU = glm::floor(u);
  const glm::vec3 f(u - floorU);
  const int i0 = int(static_cast<long long>(floorU.x) & mask), j0 = int(static_cast<long long>(floorU.y) & mask),
            k0 = int(static_cast<long long>(floorU.z) & mask);
  const int i1 = (i0 + 1) & mask, j1 = (j0 + 1) & mask, k1 = (k0 + 1) & mask;
  auto at = [&](int i, int j, int k) { return mBlend[std::size_t((k * n + j) * n + i)]; };
  const glm::vec3 x0 = glm::mix(glm::mix(at(i0, j0, k0), at(i1, j0, k0), f.x), glm::mix(at(i0, j1, k0), at(i1, j1, k0), f.x), f.y);
  const glm::vec3 x1 = glm::mix(glm::mix(at(i0, j0, k1), at(i1, j0, k1), f.x), glm::mix(at(i0, j1, k1), at(i1, j1, k1), f.x), f.y);
  return params.amplitude * glm::dvec3(glm::mix(x0, x1, f.z));
}

}  // namespace plume
