#include "flowgraph/prepared_group_cache.h"

#include <iterator>
#include <utility>

namespace plume {

std::shared_ptr<const PreparedGroup> PreparedGroupCache::find(int state, int step) {
  const auto it = mIndex.find(key(state, step));
  if (it == mIndex.end()) {
    ++mMisses;
    return nullptr;
  }
  ++mHits;
  mOrder.splice(mOrder.begin(), mOrder, it->second);  // most recent first; iterators stay valid
  return *it->second;
}

void PreparedGroupCache::erase(std::list<Entry>::iterator it) {
  mBytes -= (*it)->bytes();
  mIndex.erase(key((*it)->state, (*it)->step));
  mOrder.erase(it);
}

void PreparedGroupCache::insert(std::shared_ptr<const PreparedGroup> group) {
  if (!group) return;
  const auto old = mIndex.find(key(group->state, group->step));
  if (old != mIndex.end()) erase(old->second);
  const std::size_t bytes = group->bytes();
  if (bytes > mBudget) return;
  while (!mOrder.empty() && mBytes + bytes > mBudget) erase(std::prev(mOrder.end()));
  mBytes += bytes;
  mOrder.push_front(std::move(group));
  mIndex[key(mOrder.front()->state, mOrder.front()->step)] = mOrder.begin();
}

void PreparedGroupCache::clear() {
  mOrder.clear();
  mIndex.clear();
  mBytes = 0;
}

}  // namespace plume
