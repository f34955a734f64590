#pragma once
/// \file huge_pages.h
/// Large grids on transparent huge pages (Linux, THP in "madvise" or "always" mode): a 128³
/// solver holds about 400 MB, which in 4 KB pages is 100 000 page faults on first touch (0.7 s
/// to construct a 128³ solver on the CI machine) and many TLB misses in the gathers of
/// advection. 2 MB pages cut both.

#include <cstddef>
#include <vector>

namespace plume {

/// Asks the kernel to back [data, data + bytes) with huge pages where it can (the 2 MB-aligned
/// part of it); call before the memory is first written. No-op for buffers under 4 MB and where
/// the system has no transparent huge pages. Results never depend on it.
void adviseHugePages(void* data, std::size_t bytes);

/// v.reserve(count), the new storage advised for huge pages before anything is written to it.
/// Keeps v's content; no-op when v already has the capacity.
template <typename T>
void reserveHugePages(std::vector<T>& v, std::size_t count) {
  if (v.capacity() >= count) return;
  if (v.empty()) std::vector<T>().swap(v);  // release first: the new block is fresh, untouched
  v.reserve(count);
  adviseHugePages(static_cast<void*>(v.data() + v.size()), (v.capacity() - v.size()) * sizeof(T));
}

}  // namespace plume
