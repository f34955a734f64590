#include "solver/mass_conservation.h"

#include "core/parallel.h"

#include <algorithm>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace plume {
namespace {

constexpr std::size_t M = kMaxMassFields;

/// body(std::integral_constant<std::size_t, count>()): the loops over fields get a fixed count,
/// so their per-field sums stay in registers and the fields' additions overlap.
template <typename Body>
void withCount(std::size_t count, const Body& body) {
  switch (count) {
    case 1: body(std::integral_constant<std::size_t, 1>()); break;
    case 2: body(std::integral_constant<std::size_t, 2>()); break;
    case 3: body(std::integral_constant<std::size_t, 3>()); break;
    case 4: body(std::integral_constant<std::size_t, 4>()); break;
    default: throw std::logic_error("mass conservation: more than kMaxMassFields fields");
  }
}

/// Calls run(c0, c1) for the runs [c0, c1) of linear indices of z-slice k of `size` that lie in
/// active blocks of `mask` (nullptr: the whole slice as one run), in index order. Outside the
/// active blocks a field holds its background value exactly (see BlockMask), which adds nothing
/// to any sum here and which no correction changes, so skipping it gives the same results.
template <typename Run>
void forEachActiveRun(glm::ivec3 size, const BlockMask* mask, int k, const Run& run) {
  const std::size_t slice = std::size_t(size.x) * std::size_t(size.y);
  const std::size_t begin = slice * std::size_t(k);
  if (!mask) {
    run(begin, begin + slice);
    return;
  }
  constexpr int B = BlockMask::kBlock;
  for (int j = 0; j < size.y; ++j) {
    const std::size_t row = begin + std::size_t(size.x) * std::size_t(j);
    for (int i0 = 0; i0 < size.x; i0 += B)
      if (mask->active(i0 / B, j / B, k / B))
        run(row + std::size_t(i0), row + std::size_t(std::min(size.x, i0 + B)));
  }
}

/// M partial results per z-slice: on the stack for grids of up to 1024 slices (every grid
/// SmokeParams accepts), so that a solver step never allocates; on the heap beyond.
class SlicePartials {
 public:
  static constexpr std::size_t kStack = 1024 * M;
  explicit SlicePartials(int slices) {
    const std::size_t count = std::size_t(slices) * M;
    if (count > kStack) mHeap.resize(count);
    mData = count > kStack ? mHeap.data() : mStack;
  }
  double& operator[](std::size_t n) { return mData[n]; }

 private:
  double mStack[kStack];
  std::vector<double> mHeap;
  double* mData;
};

/// body(k, out) fills out[0 .. count-1] for z-slice k (in parallel); then out[f] = the partials
/// of field f added in slice order, as parallelSum() adds them (the same value as a one-field
/// parallelSum()).
template <typename Body>
void sumSlices(int slices, std::size_t count, double* out, const Body& body) {
  SlicePartials partial(slices);
  parallelFor(0, slices, [&](int k) { body(k, &partial[std::size_t(k) * M]); });
  for (std::size_t f = 0; f < count; ++f) {
    double sum = 0.0;
    for (int k = 0; k < slices; ++k) sum += partial[std::size_t(k) * M + f];
    out[f] = sum;
  }
}

}  // namespace

double totalMass(const ScalarGrid& q, float background) {
  const ScalarGrid* grids[1] = {&q};
  double mass;
  totalMasses(grids, &background, 1, &mass);
  return mass;
}

void totalMasses(const ScalarGrid* const* q, const float* background, std::size_t count,
                 double* masses, float* peaks, const BlockMask* mask) {
  if (count == 0) return;
  const glm::ivec3 size = q[0]->size();
  const int slices = size.z;
  SlicePartials peak(slices);
  withCount(count, [&](auto n) {
    constexpr std::size_t N = decltype(n)::value;
    sumSlices(slices, N, masses, [&](int k, double* out) {
      double s[N] = {};
      float m[N] = {};
      const float* data[N];
      float b[N];
      for (std::size_t f = 0; f < N; ++f) {
        data[f] = q[f]->data();
        b[f] = background[f];
      }
      forEachActiveRun(size, mask, k, [&](std::size_t begin, std::size_t end) {
        if (peaks) {
          for (std::size_t c = begin; c < end; ++c)
            for (std::size_t f = 0; f < N; ++f) {
              const float v = data[f][c] - b[f];
              s[f] += v;
              m[f] = v > m[f] ? v : m[f];
            }
        } else {
          for (std::size_t c = begin; c < end; ++c)
            for (std::size_t f = 0; f < N; ++f) s[f] += data[f][c] - b[f];
        }
      });
      for (std::size_t f = 0; f < N; ++f) {
        out[f] = s[f];
        peak[std::size_t(k) * M + f] = m[f];
      }
    });
  });
  if (!peaks) return;
  for (std::size_t f = 0; f < count; ++f) {
    double m = peak[f];  // parallelMax()'s order (max does not depend on it)
    for (int k = 0; k < slices; ++k) {
      const double p = peak[std::size_t(k) * M + f];
      m = p > m ? p : m;
    }
    peaks[f] = float(m);
  }
}

double outflowMass(const ScalarGrid& q, const MacGrid3& velocity,
                   const std::array<Boundary, 6>& boundaries, float dt, float cellSize,
                   float background) {
  const ScalarGrid* grids[1] = {&q};
  double out;
  outflowMasses(grids, &background, 1, velocity, boundaries, dt, cellSize, &out);
  return out;
}

void outflowMasses(const ScalarGrid* const* q, const float* background, std::size_t count,
                   const MacGrid3& velocity, const std::array<Boundary, 6>& boundaries, float dt,
                   float cellSize, double* out) {
  if (count == 0) return;
  const glm::ivec3 n = q[0]->size();
  const double scale = double(dt) / double(cellSize);
  for (std::size_t f = 0; f < count; ++f) out[f] = 0.0;
  for (int a = 0; a < 3; ++a)
    for (int side = 0; side < 2; ++side) {
      if (boundaries[std::size_t(2 * a + side)] != Boundary::Open) continue;
      const ScalarGrid& comp = velocity.component(a);
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      // Faces of this side, in a deterministic order (rows of the side's plane); each face's
      // velocity is read once for all fields.
      double sums[M];
      withCount(count, [&](auto fields) {
        constexpr std::size_t N = decltype(fields)::value;
        sumSlices(n[c], N, sums, [&](int y, double* partial) {
          double s[N] = {};
          for (int x = 0; x < n[b]; ++x) {
            glm::ivec3 cell(0), face(0);
            cell[b] = face[b] = x;
            cell[c] = face[c] = y;
            cell[a] = side == 0 ? 0 : n[a] - 1;
            face[a] = side == 0 ? 0 : n[a];
            const float un = comp(face.x, face.y, face.z) * (side == 0 ? -1.f : 1.f);
            if (!(un > 0.f)) continue;
            const std::size_t at = q[0]->index(cell.x, cell.y, cell.z);
            for (std::size_t f = 0; f < N; ++f)
              s[f] += double((*q[f])[at] - background[f]) * un * scale;
          }
          for (std::size_t f = 0; f < N; ++f) partial[f] = s[f];
        });
      });
      for (std::size_t f = 0; f < count; ++f) out[f] += sums[f];
    }
}

double restoreMass(ScalarGrid& q, double target, float background) {
  ScalarGrid* grids[1] = {&q};
  double mass, missing;
  float peak;
  totalMasses(grids, &background, 1, &mass, &peak);
  restoreMasses(grids, &target, &background, 1, &mass, &peak, &missing);
  return missing;
}

void restoreMasses(ScalarGrid* const* q, const double* targets, const float* background,
                   std::size_t count, const double* masses, const float* peaks, double* missing,
                   const BlockMask* mask) {
  if (count == 0) return;
  if (count > M) throw std::logic_error("restoreMasses: more than kMaxMassFields fields");
  const glm::ivec3 size = q[0]->size();
  const int slices = size.z;
  // What each field needs: nothing, a scale (surplus) or a gain (deficit).
  enum Action { kNone, kScale, kGain };
  Action action[M];
  float scale[M], invPeak[M];
  double left[M];
  std::size_t deficit[M], deficits = 0;
  for (std::size_t f = 0; f < count; ++f) {
    const double target = targets[f] < 0.0 ? 0.0 : targets[f];
    action[f] = kNone;
    left[f] = 0.0;
    if (masses[f] <= 0.0) {
      left[f] = target;
    } else if (masses[f] > target) {
      action[f] = kScale;
      scale[f] = float(target / masses[f]);
    } else if (peaks[f] <= 0.f) {
      left[f] = target - masses[f];
    } else {
      invPeak[f] = 1.f / peaks[f];
      deficit[deficits++] = f;
    }
  }
  // Room to grow without passing the peak: Σ e (1 - e/e_max), for the fields short of mass.
  if (deficits > 0) {
    double room[M];
    withCount(deficits, [&](auto n) {
      constexpr std::size_t N = decltype(n)::value;
      sumSlices(slices, N, room, [&](int k, double* out) {
        double s[N] = {};
        const float* data[N];
        float b[N], inv[N];
        for (std::size_t d = 0; d < N; ++d) {
          data[d] = q[deficit[d]]->data();
          b[d] = background[deficit[d]];
          inv[d] = invPeak[deficit[d]];
        }
        forEachActiveRun(size, mask, k, [&](std::size_t begin, std::size_t end) {
          for (std::size_t c = begin; c < end; ++c)
            for (std::size_t d = 0; d < N; ++d) {
              const float v = data[d][c] - b[d];
              if (v > 0.f) s[d] += double(v) * (1.0 - double(v) * inv[d]);
            }
        });
        for (std::size_t d = 0; d < N; ++d) out[d] = s[d];
      });
    });
    for (std::size_t d = 0; d < deficits; ++d) {
      const std::size_t f = deficit[d];
      const double target = targets[f] < 0.0 ? 0.0 : targets[f];
      if (room[d] <= 0.0) {
        left[f] = target - masses[f];
        continue;
      }
      const double wanted = (target - masses[f]) / room[d];
      action[f] = kGain;
      scale[f] = float(wanted < 1.0 ? wanted : 1.0);  // e + e(1 - e/e_max) <= e_max
      left[f] = wanted > 1.0 ? (target - masses[f]) - room[d] : 0.0;
    }
  }
  if (missing)
    for (std::size_t f = 0; f < count; ++f) missing[f] = left[f];
  // One pass applies every field's correction, field by field within each slice.
  parallelFor(0, slices, [&](int k) {
    forEachActiveRun(size, mask, k, [&](std::size_t begin, std::size_t end) {
      for (std::size_t f = 0; f < count; ++f) {
        if (action[f] == kNone) continue;
        float* v = q[f]->data();
        const float b = background[f], s = scale[f], inv = invPeak[f];
        if (action[f] == kScale) {
          // (q - 0) s + 0 is q s exactly: density-like fields get the plain scaling.
          for (std::size_t c = begin; c < end; ++c) v[c] = (v[c] - b) * s + b;
          continue;
        }
        for (std::size_t c = begin; c < end; ++c) {
          const float e = v[c] - b;
          if (e > 0.f) v[c] = (e + s * e * (1.f - e * inv)) + b;
        }
      }
    });
  });
}

}  // namespace plume
