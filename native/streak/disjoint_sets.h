#pragma once
/// \file disjoint_sets.h
/// Union-find for the single-linkage clustering of §3.3 ([Smoke Surfaces]): the sources joined
/// transitively by pairs with h(α,β) < h0.

#include <numeric>
#include <utility>
#include <vector>

namespace plume {

/// §3.3 union-find whose roots are always the smallest index of their set, so that the sets (and
/// every list built from them) do not depend on the order in which pairs are joined.
class DisjointSets {
 public:
  explicit DisjointSets(int n) : mParent(std::size_t(n)), mSize(std::size_t(n), 1) {
    std::iota(mParent.begin(), mParent.end(), 0);
  }
  /// The smallest index of a's set.
  int find(int a) {
    while (mParent[std::size_t(a)] != a) {
      mParent[std::size_t(a)] = mParent[std::size_t(mParent[std::size_t(a)])];  // path halving
      a = mParent[std::size_t(a)];
    }
    return a;
  }
  /// Joins the sets of a and b; returns false if they were one set already.
  bool join(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    if (b < a) std::swap(a, b);
    mParent[std::size_t(b)] = a;
    mSize[std::size_t(a)] += mSize[std::size_t(b)];
    return true;
  }
  /// Members of a's set.
  int setSize(int a) { return mSize[std::size_t(find(a))]; }

 private:
  std::vector<int> mParent;
  std::vector<int> mSize;  ///< valid at roots
};

}  // namespace plume
