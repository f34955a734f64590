#pragma once
/// \file parallel.h
/// The one parallelFor of Plume (TBB), and a deterministic parallel sum: results never depend
/// on the number of threads.

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <memory>
#include <vector>

namespace plume {

/// Calls body(n) for every n in [begin, end), in parallel. Each n must touch its own data.
template <typename Body>
void parallelFor(int begin, int end, const Body& body) {
  if (end <= begin) return;
  tbb::parallel_for(tbb::blocked_range<int>(begin, end, /*grainsize=*/1),
                    [&](const tbb::blocked_range<int>& r) {
                      for (int n = r.begin(); n != r.end(); ++n) body(n);
                    });
}

namespace detail {

/// One partial result per index of a reduction: on the stack for up to kStack indices (every
/// grid axis in practice), so that a solver step never allocates; on the heap beyond.
class Partials {
 public:
  static constexpr std::size_t kStack = 2048;
  explicit Partials(std::size_t count) : mCount(count) {
    if (count > kStack) mHeap.resize(count);
    mData = count > kStack ? mHeap.data() : mStack;
  }
  double& operator[](std::size_t n) { return mData[n]; }
  const double* begin() const { return mData; }
  const double* end() const { return mData + mCount; }

 private:
  std::size_t mCount;
  double mStack[kStack];
  std::vector<double> mHeap;
  double* mData;
};

}  // namespace detail

/// Sum of term(n) over [begin, end) as double. Partial sums are formed per n and added in
/// index order, so the result is bit-identical for any thread count.
template <typename Term>
double parallelSum(int begin, int end, const Term& term) {
  if (end <= begin) return 0.0;
  detail::Partials partial(std::size_t(end - begin));
  parallelFor(begin, end, [&](int n) { partial[std::size_t(n - begin)] = term(n); });
  double sum = 0.0;
  for (double p : partial) sum += p;
  return sum;
}

/// Maximum of term(n) over [begin, end) (max is order independent, so deterministic).
template <typename Term>
double parallelMax(int begin, int end, const Term& term) {
  if (end <= begin) return 0.0;
  detail::Partials partial(std::size_t(end - begin));
  parallelFor(begin, end, [&](int n) { partial[std::size_t(n - begin)] = term(n); });
  double m = *partial.begin();
  for (double p : partial) m = p > m ? p : m;
  return m;
}

/// Limits the threads TBB uses while this object lives (0 = no limit).
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads) {
    if (threads > 0)
      mControl = std::make_unique<tbb::global_control>(
          tbb::global_control::max_allowed_parallelism, std::size_t(threads));
  }

 private:
  std::unique_ptr<tbb::global_control> mControl;
};

}  // namespace plume
