#pragma once
/// \file banded_lu.h
/// LU factorisation with partial pivoting of a banded matrix (LAPACK dgbtrf's storage scheme),
/// for the B-spline systems of the §3.3 surface: the collocation matrices of the interpolation
/// (row i has at most `order` non-zeros near the diagonal) and the normal equations of the
/// least-squares fit (bandwidth order − 1), so factor and solve cost O(n · order²).

#include <glm/glm.hpp>

#include <vector>

namespace plume {

/// A square n × n matrix with `lower` sub- and `upper` super-diagonals, factorised in place.
class BandedLu {
 public:
  BandedLu(int n, int lower, int upper);

  int size() const { return mN; }
  /// Sets A(i, j); |i - j| must be inside the band given to the constructor.
  void set(int i, int j, double value);
  /// A(i, j) += value (normal equations are sums of outer products); same band rule as set().
  void add(int i, int j, double value);
  /// Factorises PA = LU with partial pivoting inside the band. Throws std::runtime_error if a
  /// pivot is zero (the system has no unique solution).
  void factor();
  /// Solves A x = b in place for one right-hand side per row (three coordinates at once).
  void solve(std::vector<glm::dvec3>& b) const;

 private:
  double& at(int i, int j) { return mBand[std::size_t(j) * mLd + std::size_t(mLower + mUpper + i - j)]; }
  double at(int i, int j) const { return mBand[std::size_t(j) * mLd + std::size_t(mLower + mUpper + i - j)]; }

  int mN, mLower, mUpper;
  std::size_t mLd;  ///< rows of band storage per column: 2 lower + upper + 1 (room for fill-in)
  std::vector<double> mBand;
  std::vector<int> mPivot;
  bool mFactored = false;
};

}  // namespace plume
