#include "nurbs/banded_lu.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace plume {

BandedLu::BandedLu(int n, int lower, int upper)
    : mN(n), mLower(lower), mUpper(upper), mLd(std::size_t(2 * lower + upper + 1)) {
  if (n < 1 || lower < 0 || upper < 0) throw std::invalid_argument("BandedLu: bad size or band");
  mBand.assign(mLd * std::size_t(n), 0.0);
  mPivot.assign(std::size_t(n), 0);
}

void BandedLu::set(int i, int j, double value) {
  if (i < 0 || j < 0 || i >= mN || j >= mN || i - j > mLower || j - i > mUpper)
    throw std::invalid_argument("BandedLu::set: entry outside the band");
  at(i, j) = value;
  mFactored = false;
}

void BandedLu::add(int i, int j, double value) {
  if (i < 0 || j < 0 || i >= mN || j >= mN || i - j > mLower || j - i > mUpper)
    throw std::invalid_argument("BandedLu::add: entry outside the band");
  at(i, j) += value;
  mFactored = false;
}

void BandedLu::factor() {
  // Row interchanges move entries at most `lower` rows up, so U gets lower + upper
  // super-diagonals: the extra `lower` storage rows on top of each column hold that fill-in.
  const int width = mLower + mUpper;
  for (int j = 0; j < mN; ++j) {
    const int lastRow = std::min(mN - 1, j + mLower);
    const int lastCol = std::min(mN - 1, j + width);
    int p = j;
    for (int i = j + 1; i <= lastRow; ++i)
      if (std::abs(at(i, j)) > std::abs(at(p, j))) p = i;
    mPivot[std::size_t(j)] = p;
    if (at(p, j) == 0.0) throw std::runtime_error("B-spline system is singular");
    if (p != j)
      for (int c = j; c <= lastCol; ++c) std::swap(at(p, c), at(j, c));
    const double pivot = at(j, j);
    for (int i = j + 1; i <= lastRow; ++i) {
      const double l = at(i, j) / pivot;
      at(i, j) = l;
      if (l == 0.0) continue;
      for (int c = j + 1; c <= lastCol; ++c) at(i, c) -= l * at(j, c);
    }
  }
  mFactored = true;
}

void BandedLu::solve(std::vector<glm::dvec3>& b) const {
  if (!mFactored) throw std::logic_error("BandedLu::solve before factor");
  if (b.size() != std::size_t(mN)) throw std::invalid_argument("BandedLu::solve: size mismatch");
  // Forward: the same interchanges and eliminations, in the order factor() made them.
  for (int j = 0; j < mN; ++j) {
    const int p = mPivot[std::size_t(j)];
    if (p != j) std::swap(b[std::size_t(p)], b[std::size_t(j)]);
    const int lastRow = std::min(mN - 1, j + mLower);
    for (int i = j + 1; i <= lastRow; ++i) b[std::size_t(i)] -= at(i, j) * b[std::size_t(j)];
  }
  // Back substitution with U (upper bandwidth lower + upper).
  const int width = mLower + mUpper;
  for (int j = mN - 1; j >= 0; --j) {
    b[std::size_t(j)] /= at(j, j);
    const int firstRow = std::max(0, j - width);
    for (int i = firstRow; i < j; ++i) b[std::size_t(i)] -= at(i, j) * b[std::size_t(j)];
  }
}

}  // namespace plume
