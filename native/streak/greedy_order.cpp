#include "streak/greedy_order.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace plume {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// A candidate for the next member: its h to an end and its position in `members`.
struct Nearest {
  double h = kInf;
  int pos = INT_MAX;
};

/// Strictly better: smaller h, then the earlier member.
bool better(const Nearest& x, const Nearest& y) { return x.h != y.h ? x.h < y.h : x.pos < y.pos; }

/// A computed bound L proves h > x when L >= x⁺ + slack(x⁺), with x⁺ the next double above x.
bool provesFarther(const StreakProjection& q, double bound, double x) {
  const double above = std::nextafter(x, kInf);
  return bound >= above + q.slack(above);
}

/// The greedy chain over one set of members (positions 0..k-1 in the order given).
class GreedyChain {
 public:
  GreedyChain(const StreakDistances& d, const std::vector<int>& members)
      : mD(d), mMembers(members), mPosOf(std::size_t(d.size()), -1), mLeft(members.size(), 1),
        mLeftCount(int(members.size())) {
    for (std::size_t p = 0; p < members.size(); ++p) {
      const int m = members[p];
      if (m < 0 || m >= d.size())
        throw std::invalid_argument("member " + std::to_string(m) + " is not in h (size " +
                                    std::to_string(d.size()) + ")");
      if (mPosOf[std::size_t(m)] >= 0)
        throw std::invalid_argument("member " + std::to_string(m) + " repeats");
      mPosOf[std::size_t(m)] = int(p);
    }
  }

  std::vector<int> order() {
    if (mMembers.size() < 2) return mMembers;
    const std::pair<int, int> first = closestPair();
    take(first.first);
    take(first.second);
    int front = mMembers[std::size_t(first.first)], back = mMembers[std::size_t(first.second)];
    std::vector<int> atFront, atBack{front, back};  // atFront in attachment order
    Nearest nf = nearest(front), nb = nearest(back);
    while (mLeftCount > 0) {
      const bool toBack = better(nb, nf);  // equal: the front end first
      const int pos = toBack ? nb.pos : nf.pos;
      const int m = mMembers[std::size_t(pos)];
      take(pos);
      if (toBack) {
        atBack.push_back(m);
        back = m;
        nb = nearest(back);
        if (nf.pos == pos) nf = nearest(front);
      } else {
        atFront.push_back(m);
        front = m;
        nf = nearest(front);
        if (nb.pos == pos) nb = nearest(back);
      }
    }
    std::vector<int> out(atFront.rbegin(), atFront.rend());
    out.insert(out.end(), atBack.begin(), atBack.end());
    return out;
  }

 private:
  void take(int pos) {
    mLeft[std::size_t(pos)] = 0;
    --mLeftCount;
  }

  /// Positions (pa < pb) of the pair with the smallest (h, pa, pb).
  std::pair<int, int> closestPair() const {
    const int k = int(mMembers.size());
    double best = kInf;
    std::pair<int, int> at{-1, -1};
    for (int pa = 0; pa < k; ++pa) {
      const int a = mMembers[std::size_t(pa)];
      for (int i = 0; i < mD.degree(a); ++i) {
        const int pb = mPosOf[std::size_t(mD.neighbours(a)[i])];
        if (pb <= pa) continue;  // not a member, or seen from the other side
        const double h = mD.neighbourDistances(a)[i];
        if (h < best || (h == best && std::make_pair(pa, pb) < at)) {
          best = h;
          at = {pa, pb};
        }
      }
    }
    if (at.first >= 0) return at;  // every pair below the reach is held: this is the minimum
    // No two members closer than the reach: every pair, the bound skipping the hopeless ones.
    const StreakProjection& q = mD.projection();
    for (int pa = 0; pa < k; ++pa)
      for (int pb = pa + 1; pb < k; ++pb) {
        const int a = mMembers[std::size_t(pa)], b = mMembers[std::size_t(pb)];
        if (at.first >= 0 && provesFarther(q, q.lowerBound(a, b, kInf), best)) continue;
        const double h = mD.distance(a, b);
        if (at.first < 0 || h < best) {  // scanned in (pa, pb) order: the first minimum stays
          best = h;
          at = {pa, pb};
        }
      }
    return at;
  }

  /// The remaining member closest to `end`, smallest (h, position).
  Nearest nearest(int end) const {
    Nearest best;
    if (mLeftCount == 0) return best;
    for (int i = 0; i < mD.degree(end); ++i) {
      const int p = mPosOf[std::size_t(mD.neighbours(end)[i])];
      if (p < 0 || !mLeft[std::size_t(p)]) continue;
      const Nearest c{mD.neighbourDistances(end)[i], p};
      if (better(c, best)) best = c;
    }
    if (best.pos != INT_MAX) return best;  // held pairs are exactly those with h < reach
    // Every remaining member is at h >= reach: rank them by the bound, compute h in that order.
    const StreakProjection& q = mD.projection();
    std::vector<std::pair<double, int>> ranked;
    ranked.reserve(std::size_t(mLeftCount));
    for (std::size_t p = 0; p < mMembers.size(); ++p)
      if (mLeft[p]) ranked.emplace_back(q.lowerBound(end, mMembers[p], kInf), int(p));
    std::sort(ranked.begin(), ranked.end());
    for (const auto& [bound, p] : ranked) {
      if (best.pos != INT_MAX && provesFarther(q, bound, best.h)) break;  // and all after it
      const Nearest c{mD.distance(end, mMembers[std::size_t(p)]), p};
      if (better(c, best)) best = c;
    }
    return best;
  }

  const StreakDistances& mD;
  const std::vector<int>& mMembers;
  std::vector<int> mPosOf;  ///< position in members of each group member, −1 if absent
  std::vector<char> mLeft;  ///< by position: not yet in the chain
  int mLeftCount;
};

}  // namespace

std::vector<int> orderGreedy(const StreakDistances& h, const std::vector<int>& members) {
  return GreedyChain(h, members).order();
}

}  // namespace plume
