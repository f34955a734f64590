#include "streak/streak_moments.h"

#include "core/parallel.h"

namespace plume {

StreakMoments streakMoments(const StreakGroup& g) {
  const int n = g.size(), frames = g.usedFrameCount();
  StreakMoments m;
  m.meanLine.assign(g.coordinateCount(), 0.0);
  if (n == 0) return m;
  std::vector<std::size_t> first(std::size_t(frames) + 1, 0);  // first coordinate of each frame
  for (int f = 0; f < frames; ++f)
    first[std::size_t(f) + 1] = first[std::size_t(f)] + 3 * std::size_t(g.particleCount(f));
  std::vector<double> frameDeviation(std::size_t(frames), 0.0);
  parallelFor(0, frames, [&](int f) {
    const std::size_t count = 3 * std::size_t(g.particleCount(f));
    double* mean = m.meanLine.data() + first[std::size_t(f)];
    for (int a = 0; a < n; ++a) {
      const float* x = g.line(f, a);
      for (std::size_t k = 0; k < count; ++k) mean[k] += double(x[k]);
    }
    for (std::size_t k = 0; k < count; ++k) mean[k] /= double(n);
    // Squared deviations from the mean, per coordinate over the members, then over coordinates.
    std::vector<double> deviation(count, 0.0);
    for (int a = 0; a < n; ++a) {
      const float* x = g.line(f, a);
      for (std::size_t k = 0; k < count; ++k) {
        const double d = double(x[k]) - mean[k];
        deviation[k] += d * d;
      }
    }
    double s = 0.0;
    for (double d : deviation) s += d;
    frameDeviation[std::size_t(f)] = s;
  });
  double perSource = 0.0;  // Σ_t (1/N(t)) Σ_i Σ_α |p − m|²
  for (int f = 0; f < frames; ++f)
    perSource += frameDeviation[std::size_t(f)] / double(g.particleCount(f));
  m.pairSum = double(n) * perSource;
  m.meanDistance = n < 2 ? 0.0 : 2.0 * perSource / double(n - 1);
  return m;
}

}  // namespace plume
