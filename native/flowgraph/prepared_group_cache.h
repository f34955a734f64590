#pragma once
/// \file prepared_group_cache.h
/// The prepared groups (prepared_group.h) of recently visited nodes, kept between visits of the
/// random walk ([Graph Fire Synthesis] §5.1-5.2): a walk revisits nodes (600 campfire frames
/// visit each of its 453 nodes about four times), and reading a group from its pathline file
/// and preparing it (eq. 13's trapezoid sums) costs far more than emitting a prepared one,
/// which is a pointer copy. Least recently used first out, within a byte budget.

#include "flowgraph/prepared_group.h"

#include <cstddef>
#include <cstdint>
#include <list>
#include <memory>
#include <unordered_map>

namespace plume {

/// LRU cache of prepared groups keyed (state, node step), holding at most budget() bytes
/// (PreparedGroup::bytes()). Groups are shared: one evicted while a synthesizer slot still
/// emits it stays alive until that slot lets go. Not thread-safe (one synthesizer uses it).
class PreparedGroupCache {
 public:
  /// `budgetBytes` 0: nothing is kept (every find() misses).
  explicit PreparedGroupCache(std::size_t budgetBytes = 0) : mBudget(budgetBytes) {}

  /// The group of (state, step) if held, made the most recently used (a hit); else nullptr (a
  /// miss: the caller reads and prepares it, then insert()s it).
  std::shared_ptr<const PreparedGroup> find(int state, int step);
  /// Holds `group` under (group->state, group->step) as the most recently used (replacing a
  /// group of that key), then evicts the least recently used until bytes() <= budget(). A group
  /// larger than the whole budget is not held.
  void insert(std::shared_ptr<const PreparedGroup> group);
  /// Drops every group (the counters stay).
  void clear();

  std::size_t budget() const { return mBudget; }
  std::size_t bytes() const { return mBytes; }
  std::size_t size() const { return mOrder.size(); }
  long long hits() const { return mHits; }
  long long misses() const { return mMisses; }

 private:
  using Entry = std::shared_ptr<const PreparedGroup>;
  static std::uint64_t key(int state, int step) {
    return (std::uint64_t(std::uint32_t(state)) << 32) | std::uint32_t(step);
  }
  void erase(std::list<Entry>::iterator it);

  std::size_t mBudget, mBytes = 0;
  std::list<Entry> mOrder;  ///< most recently used first
  std::unordered_map<std::uint64_t, std::list<Entry>::iterator> mIndex;
  long long mHits = 0, mMisses = 0;
};

}  // namespace plume
