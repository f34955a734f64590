#pragma once
/// \file rng.h
/// Explicitly seeded random numbers: every random choice in Plume comes from one of these, so
/// the same settings and seed give the same result at any thread count.

#include <cmath>
#include <cstdint>

namespace plume {

/// SplitMix64 generator; Rng(seed, stream) gives an independent sequence per stream (per source,
/// per particle...), so parallel code can draw without sharing state.
class Rng {
 public:
  explicit Rng(std::uint64_t seed, std::uint64_t stream = 0)
      : mState(seed * 0x9E3779B97F4A7C15ull ^ (stream + 0x632BE59BD9B4E019ull) * 0xD1B54A32D192ED03ull) {
    next();
  }
  std::uint64_t next() {
    std::uint64_t z = (mState += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1).
  double uniform() { return double(next() >> 11) * (1.0 / 9007199254740992.0); }
  /// Uniform in [a, b).
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  /// Standard normal N(0, 1) (Box–Muller, two uniforms per draw: no cached state, so the
  /// sequence depends only on the seed and the number of draws).
  double normal() {
    const double u1 = 1.0 - uniform(), u2 = uniform();  // u1 in (0, 1]: log(u1) finite
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }

 private:
  std::uint64_t mState;
};

}  // namespace plume
