/// \file cost_tiles.cpp
/// One tile of node pairs of the cost matrix of eq. 9-10 (§4.3).
///
/// c_ij² is a squared Euclidean distance between two groups' sample arrays (5 |Ω| L floats
/// each: three velocity components, density, temperature), so the work is N(N−1)/2 such
/// distances: for N = 1000, |Ω| = 3200, L = 48, 5·10^5 pairs × 7.7·10^5 values.
/// - Direct form Σ (a − b)², not the Gram form |a|² + |b|² − 2 a·b: the small costs, the only
///   ones that become transitions, are exactly where the Gram form cancels (relative error
///   ≈ float ε · |a|² / c², i.e. no digits left for near-identical groups). The build has no FMA
///   (core/cpu_features.h), so the Gram form would save one subtraction of three operations.
/// - Tiles of kCostTile × kCostTile groups: each task takes one tile (rows I, columns J ≥ I) and
///   walks the particles in chunks of kPathlinesPerSum pathlines; a chunk of the tile's
///   2 kCostTile groups (64 × 8 × 5 × 48 floats ≈ 490 KB at L = 48) stays in L2 (1 MB here)
///   while its kCostTile² pairs use it, instead of each pair streaming 6 MB of groups from memory.
/// - kRows rows against one column per pass (register blocking): one column load serves
///   kRows pairs. Measured at N = 120 on this machine (1 thread, AVX2): 1.0·10^10 sample
///   differences per second with one row, 1.25·10^10 with 4, 1.39·10^10 with 8 (and 8 pathlines
///   per chunk); the SSE baseline runs at about half.
/// - Accumulation: float squares in kLanes fixed lanes over one chunk (≤ 8·3L = 1152 values, a
///   lane sums ≤ 144 of them: relative error below 144 float ε ≈ 9·10^-6 on c², half that on c,
///   typically ~10^-7), the lanes added in a fixed tree, then each chunk's sum added in double
///   in particle order. Each entry is computed by one task in that fixed order, from its two
///   groups only (whichever tile or block holds them): the same bits at any thread count, in
///   memory or streamed, and for the SSE and AVX2 clones (GCC vector extensions: the same float
///   operations per lane, no FMA).

#include "flowgraph/cost_tiles.h"

#include "core/cpu_features.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

namespace plume {
namespace {

constexpr std::size_t kPathlinesPerSum = 8;
constexpr int kRows = 8;
constexpr int kLanes = 8;

/// kLanes floats (GCC vector extension: one AVX2 register, or two SSE ones in the baseline
/// clone; the same IEEE operations per lane either way).
typedef float Lanes __attribute__((vector_size(kLanes * sizeof(float))));

inline void load(Lanes& v, const float* p) { std::memcpy(&v, p, sizeof v); }

/// The lanes of v in the order i0..i7 (GCC's __builtin_shuffle, clang's
/// __builtin_shufflevector: the same permutation, so the same sums in either build).
#if defined(__clang__)
#define laneShuffle(v, ...) __builtin_shufflevector(v, v, __VA_ARGS__)
#else
typedef int LaneIndex __attribute__((vector_size(kLanes * sizeof(int))));
#define laneShuffle(v, ...) __builtin_shuffle(v, LaneIndex{__VA_ARGS__})
#endif

/// out[r] = Σ_k (a_r,k − b_k)² for k < n and the kRows rows a_r against one column b: squares
/// summed in float in kLanes lanes per row (lane k mod kLanes; the tail is padded with zeros,
/// which add exactly 0), the lanes then added in a fixed tree. One column load serves kRows
/// rows: the loads, not the arithmetic, bound this loop.
inline void squaredDistances(const float* const* a, const float* b, std::size_t n, float* out) {
  Lanes s[kRows] = {};
  std::size_t k = 0;
  for (; k + kLanes <= n; k += kLanes) {
    Lanes bk, d;
    load(bk, b + k);
    for (int r = 0; r < kRows; ++r) {
      load(d, a[r] + k);
      d -= bk;
      s[r] += d * d;
    }
  }
  if (k < n) {
    float bt[kLanes] = {};
    std::memcpy(bt, b + k, (n - k) * sizeof(float));
    Lanes bk, d;
    load(bk, bt);
    for (int r = 0; r < kRows; ++r) {
      float at[kLanes] = {};
      std::memcpy(at, a[r] + k, (n - k) * sizeof(float));
      load(d, at);
      d -= bk;
      s[r] += d * d;
    }
  }
  // Fixed tree ((s0 + s4) + (s2 + s6)) + ((s1 + s5) + (s3 + s7)) per row, as vector halves.
  for (int r = 0; r < kRows; ++r) {
    Lanes v = s[r] + laneShuffle(s[r], 4, 5, 6, 7, 0, 1, 2, 3);
    v += laneShuffle(v, 2, 3, 0, 1, 2, 3, 0, 1);
    v += laneShuffle(v, 1, 0, 1, 0, 1, 0, 1, 0);
    out[r] = v[0];
  }
}

/// The three squared differences of eq. 9 (velocity, density, temperature), summed over the
/// samples and particles of every pair (rows[i], cols[j]) of a tile, into sums[3 (i kCostTile + j)..].
/// On a diagonal tile (rows == cols) only j > i is kept. Rows go kRows at a time (a short last
/// block repeats its last row, whose sums are dropped); the particles kPathlinesPerSum at a
/// time, so that the chunk of all the tile's groups stays in cache while every pair uses it.
PLUME_AVX2_CLONES void tileSums(const GroupArrays* rows, int nRows, const GroupArrays* cols, int nCols,
                                bool diagonal, std::size_t particles, std::size_t samples, double* sums) {
  for (std::size_t p0 = 0; p0 < particles; p0 += kPathlinesPerSum) {
    const std::size_t o = p0 * samples, n = std::min(kPathlinesPerSum, particles - p0) * samples;
    for (int i0 = 0; i0 < nRows; i0 += kRows) {
      const float *au[kRows], *ad[kRows], *at[kRows];
      for (int r = 0; r < kRows; ++r) {
        const GroupArrays& a = rows[std::min(i0 + r, nRows - 1)];
        au[r] = a.velocity + 3 * o;
        ad[r] = a.density + o;
        at[r] = a.temperature + o;
      }
      for (int j = diagonal ? i0 + 1 : 0; j < nCols; ++j) {
        const GroupArrays& b = cols[j];
        float u[kRows], d[kRows], t[kRows];
        squaredDistances(au, b.velocity + 3 * o, 3 * n, u);
        squaredDistances(ad, b.density + o, n, d);
        squaredDistances(at, b.temperature + o, n, t);
        for (int r = 0; r < kRows && i0 + r < nRows; ++r) {
          if (diagonal && j <= i0 + r) continue;
          double* s = sums + 3 * (std::size_t(i0 + r) * kCostTile + std::size_t(j));
          s[0] += u[r];
          s[1] += d[r];
          s[2] += t[r];
        }
      }
    }
  }
}

}  // namespace

GroupArrays groupArrays(const PathlineGroup& g) {
  return {&g.velocity.front().x, g.density.data(), g.temperature.data()};
}

void costTile(const GroupArrays* rows, int i0, int nRows, const GroupArrays* cols, int j0, int nCols,
              const PathlineLayout& layout, const FlowGraphParams& params, CostMatrix& cost) {
  // Σ_s Δt_n (1/|Ω|) Σ_x: the rectangle rule of eq. 9 applied to the means of eq. 10.
  const double scale = double(layout.sampleDt) / double(layout.particles);
  const bool diagonal = i0 == j0;
  std::vector<double> sums(3 * std::size_t(kCostTile) * kCostTile, 0.0);
  tileSums(rows, nRows, cols, nCols, diagonal, std::size_t(layout.particles), std::size_t(layout.samples),
           sums.data());
  for (int i = 0; i < nRows; ++i)
    for (int j = diagonal ? i + 1 : 0; j < nCols; ++j) {
      const double* s = &sums[3 * (std::size_t(i) * kCostTile + std::size_t(j))];
      cost.set(i0 + i, j0 + j, std::sqrt(scale * (s[0] + params.alpha * s[1] + params.beta * s[2])));
    }
}

}  // namespace plume
