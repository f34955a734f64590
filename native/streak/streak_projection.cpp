#include "streak/streak_projection.h"

#include "core/parallel.h"
#include "core/rng.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace plume {
namespace {

/// Column j of a column-major matrix with `rows` rows.
double* column(std::vector<double>& m, std::size_t rows, int j) {
  return m.data() + rows * std::size_t(j);
}

double dot(const double* a, const double* b, std::size_t n) {
  double s = 0.0;
  for (std::size_t k = 0; k < n; ++k) s += a[k] * b[k];
  return s;
}

/// dot() with eight independent partial sums, for the long Gram-matrix products (the PCA only
/// needs them approximately; the order is still fixed, so they are deterministic).
double fastDot(const double* a, const double* b, std::size_t n) {
  double s[8] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  std::size_t k = 0;
  for (; k + 8 <= n; k += 8)
    for (std::size_t j = 0; j < 8; ++j) s[j] += a[k + j] * b[k + j];
  for (std::size_t j = 0; k + j < n; ++j) s[j] += a[k + j] * b[k + j];
  return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

/// Directions are applied eight at a time: the accumulators stay in registers.
constexpr int kChunk = 8;

/// Modified Gram–Schmidt, twice (orthonormal to rounding), on the columns of a column-major
/// matrix, in order. A column that keeps less than `keep` of its norm after removing the earlier
/// ones is dependent: it is set to zero and reported false.
std::vector<bool> orthonormalize(std::vector<double>& m, std::size_t rows, int cols, double keep) {
  std::vector<bool> kept(std::size_t(cols), false);
  for (int j = 0; j < cols; ++j) {
    double* v = column(m, rows, j);
    const double before = std::sqrt(dot(v, v, rows));
    for (int pass = 0; pass < 2; ++pass)
      for (int i = 0; i < j; ++i) {
        if (!kept[std::size_t(i)]) continue;
        const double* u = column(m, rows, i);
        const double c = dot(u, v, rows);
        for (std::size_t k = 0; k < rows; ++k) v[k] -= c * u[k];
      }
    const double after = std::sqrt(dot(v, v, rows));
    if (!(after > keep * before) || after == 0.0) {
      std::fill(v, v + rows, 0.0);
      continue;
    }
    for (std::size_t k = 0; k < rows; ++k) v[k] /= after;
    kept[std::size_t(j)] = true;
  }
  return kept;
}

}  // namespace

void ProjectionParams::validate() const {
  if (rank < 0 || rank > 64)
    throw std::invalid_argument("projection rank must be in [0, 64] (got " +
                                std::to_string(rank) + ")");
  if (sampleSize < 2 || sampleSize > 4096)
    throw std::invalid_argument("projection sample size must be in [2, 4096] (got " +
                                std::to_string(sampleSize) + ")");
  if (iterations < 1 || iterations > 1000)
    throw std::invalid_argument("projection iterations must be in [1, 1000] (got " +
                                std::to_string(iterations) + ")");
  if (minSize < 0)
    throw std::invalid_argument("projection min size must be >= 0 (got " +
                                std::to_string(minSize) + ")");
}

StreakProjection::StreakProjection(int size, int rank, std::vector<double> coords, double margin)
    : mSize(size), mRank(rank), mCoords(std::move(coords)), mMargin(margin) {}

double StreakProjection::lowerBound(int a, int b, double limit) const {
  const double* qa = coords(a);
  const double* qb = coords(b);
  double s = 0.0;
  for (int j = 0; j < mRank; ++j) {
    const double d = qa[j] - qb[j];
    s += d * d;
    if (s >= limit) return s;
  }
  return s;
}

StreakProjection projectStreaks(const StreakGroup& g, const std::vector<double>& meanLine,
                                const ProjectionParams& params) {
  params.validate();
  const int n = g.size();
  const std::size_t D = g.coordinateCount();
  if (meanLine.size() != D)
    throw std::invalid_argument("mean line has " + std::to_string(meanLine.size()) +
                                " coordinates, the group " + std::to_string(D));
  if (n < params.minSize) return StreakProjection(n, 0, {}, 0.0);  // no bound: every pair exactly
  // 1/√N(t) of each coordinate: x_α = p(α,t,i)/√N(t).
  std::vector<double> scale;
  scale.reserve(D);
  for (int f = 0; f < g.usedFrameCount(); ++f)
    scale.insert(scale.end(), 3 * std::size_t(g.particleCount(f)),
                 1.0 / std::sqrt(double(g.particleCount(f))));
  // Embedding of member a, centred: y = (x − m)/√N.
  auto embed = [&](int a, double* y) {
    std::size_t k = 0;
    for (int f = 0; f < g.usedFrameCount(); ++f) {
      const float* x = g.line(f, a);
      for (std::size_t c = 0; c < 3 * std::size_t(g.particleCount(f)); ++c, ++k)
        y[k] = (double(x[c]) - meanLine[k]) * scale[k];
    }
  };

  // PCA of an evenly spaced sample through its Gram matrix G = Y Yᵀ (s × s).
  const int s = std::min(n, params.sampleSize);
  const int r = std::min(params.rank, s);
  std::vector<double> basis;  // D × rank, column-major
  int rank = 0;
  if (r > 0 && D > 0) {
    std::vector<double> Y(D * std::size_t(s));  // column-major: column j = sample j
    parallelFor(0, s, [&](int j) { embed(int(std::int64_t(j) * n / s), column(Y, D, j)); });
    std::vector<double> G(std::size_t(s) * std::size_t(s));
    parallelFor(0, s, [&](int i) {
      for (int j = i; j < s; ++j)
        G[std::size_t(i) * std::size_t(s) + std::size_t(j)] =
            G[std::size_t(j) * std::size_t(s) + std::size_t(i)] =
                fastDot(column(Y, D, i), column(Y, D, j), D);
    });
    // Subspace iteration from a seeded start: Q ← orth(G Q). Column j tends to the j-th
    // principal direction (modified Gram–Schmidt keeps the earlier columns first).
    std::vector<double> Q(std::size_t(s) * std::size_t(r)), Z(Q.size());
    Rng rng(/*seed=*/0x5eedu, /*stream=*/std::uint64_t(s));
    for (double& q : Q) q = rng.normal();
    orthonormalize(Q, std::size_t(s), r, 1e-12);
    for (int it = 0; it < params.iterations; ++it) {
      parallelFor(0, r, [&](int j) {
        const double* q = column(Q, std::size_t(s), j);
        double* z = column(Z, std::size_t(s), j);
        for (int i = 0; i < s; ++i)
          z[i] = dot(G.data() + std::size_t(i) * std::size_t(s), q, std::size_t(s));
      });
      Q.swap(Z);
      orthonormalize(Q, std::size_t(s), r, 1e-12);
    }
    // Directions in the embedding: V = Yᵀ Q, orthonormalized in D dimensions.
    std::vector<double> V(D * std::size_t(r), 0.0);
    parallelFor(0, r, [&](int j) {
      double* v = column(V, D, j);
      const double* q = column(Q, std::size_t(s), j);
      for (int i = 0; i < s; ++i) {
        const double* y = column(Y, D, i);
        for (std::size_t k = 0; k < D; ++k) v[k] += q[i] * y[k];
      }
    });
    const std::vector<bool> kept = orthonormalize(V, D, r, 1e-6);
    rank = int(std::count(kept.begin(), kept.end(), true));
    // Weights W = V/√N of the kept columns in chunks of eight (zero columns pad the last):
    // chunk c holds D rows of eight, basis[(c·D + k)·8 + j] = V_k,(8c+j) / √N.
    basis.assign(D * std::size_t((rank + kChunk - 1) / kChunk * kChunk), 0.0);
    int col = 0;
    for (int j = 0; j < r; ++j) {
      if (!kept[std::size_t(j)]) continue;
      const double* v = column(V, D, j);
      double* w = basis.data() + std::size_t(col / kChunk) * D * kChunk + std::size_t(col % kChunk);
      for (std::size_t k = 0; k < D; ++k) w[k * kChunk] = v[k] * scale[k];
      ++col;
    }
  }

  // q_α = Σ_k (x_k − m_k) W_k and |y_α|², every member.
  std::vector<double> coords(std::size_t(n) * std::size_t(rank), 0.0);
  std::vector<double> norm2(std::size_t(n), 0.0);
  parallelFor(0, n, [&](int a) {
    double* q = coords.data() + std::size_t(a) * std::size_t(rank);
    double nn = 0.0;
    for (int c0 = 0; c0 < rank; c0 += kChunk) {
      const double* w = basis.data() + std::size_t(c0 / kChunk) * D * kChunk;
      double acc[kChunk] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
      std::size_t k = 0;
      for (int f = 0; f < g.usedFrameCount(); ++f) {
        const float* x = g.line(f, a);
        for (std::size_t c = 0; c < 3 * std::size_t(g.particleCount(f)); ++c, ++k) {
          const double d = double(x[c]) - meanLine[k];
          for (int j = 0; j < kChunk; ++j) acc[j] += d * w[k * kChunk + std::size_t(j)];
        }
      }
      for (int j = 0; j < std::min(kChunk, rank - c0); ++j) q[c0 + j] = acc[j];
    }
    std::size_t k = 0;
    for (int f = 0; f < g.usedFrameCount(); ++f) {
      const float* x = g.line(f, a);
      const double w = 1.0 / double(g.particleCount(f));
      for (std::size_t c = 0; c < 3 * std::size_t(g.particleCount(f)); ++c, ++k) {
        const double d = double(x[c]) - meanLine[k];
        nn += d * d * w;
      }
    }
    norm2[std::size_t(a)] = nn;
  });
  // Rounding of q_j is <= (D + 2) u |y_α| per coordinate (Cauchy–Schwarz, |V_j| = 1); squared
  // and summed over the rank, the bound moves by < 8 (D + 2) u √rank max|y|². Allow 4× that.
  const double maxNorm2 = n > 0 ? *std::max_element(norm2.begin(), norm2.end()) : 0.0;
  const double margin =
      32.0 * double(D + 16) * 0x1p-53 * (std::sqrt(double(rank)) + 1.0) * maxNorm2;
  return StreakProjection(n, rank, std::move(coords), margin);
}

}  // namespace plume
