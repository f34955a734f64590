#pragma once
/// \file grid3.h
/// Dense 3-D arrays of the solver (cell-centred scalars, flags) with x varying fastest.

#include "core/huge_pages.h"

#include <glm/glm.hpp>

#include <cstddef>
#include <algorithm>
#include <cstdint>
#include <vector>

namespace plume {

/// A dense nx*ny*nz array stored x-fastest: index(i,j,k) = i + nx*(j + ny*k).
/// Streams well: every kernel walks k, then j, then i.
template <typename T>
class Grid3 {
 public:
  Grid3() = default;
  explicit Grid3(glm::ivec3 size, T value = T(0)) { resize(size, value); }

  void resize(glm::ivec3 size, T value = T(0)) {
    mSize = size;
    const std::size_t count = std::size_t(size.x) * std::size_t(size.y) * std::size_t(size.z);
    if (mData.capacity() < count) {
      mData.clear();
      reserveHugePages(mData, count);
    }
    mData.assign(count, value);
  }
  /// Changes the shape without initialising values; never reallocates when the new count fits in
  /// what was reserved before (scratch grids reuse one buffer for u, v and w shapes).
  void reshape(glm::ivec3 size) {
    mSize = size;
    const std::size_t count = std::size_t(size.x) * std::size_t(size.y) * std::size_t(size.z);
    reserveHugePages(mData, count);
    mData.resize(count);
  }
  void reserve(std::size_t count) { reserveHugePages(mData, count); }
  void fill(T value) { std::fill(mData.begin(), mData.end(), value); }

  glm::ivec3 size() const { return mSize; }
  std::size_t count() const { return mData.size(); }
  std::size_t index(int i, int j, int k) const {
    return std::size_t(i) + std::size_t(mSize.x) * (std::size_t(j) + std::size_t(mSize.y) * std::size_t(k));
  }
  /// Stride between (i,j,k) and (i,j+1,k), and between (i,j,k) and (i,j,k+1).
  std::ptrdiff_t strideY() const { return mSize.x; }
  std::ptrdiff_t strideZ() const { return std::ptrdiff_t(mSize.x) * mSize.y; }

  bool inside(int i, int j, int k) const {
    return i >= 0 && j >= 0 && k >= 0 && i < mSize.x && j < mSize.y && k < mSize.z;
  }
  T& operator()(int i, int j, int k) { return mData[index(i, j, k)]; }
  const T& operator()(int i, int j, int k) const { return mData[index(i, j, k)]; }
  T& operator[](std::size_t n) { return mData[n]; }
  const T& operator[](std::size_t n) const { return mData[n]; }
  /// Value at (i,j,k) with indices clamped to the grid (constant extrapolation).
  T clampedAt(int i, int j, int k) const {
    i = glm::clamp(i, 0, mSize.x - 1);
    j = glm::clamp(j, 0, mSize.y - 1);
    k = glm::clamp(k, 0, mSize.z - 1);
    return mData[index(i, j, k)];
  }

  T* data() { return mData.data(); }
  const T* data() const { return mData.data(); }
  std::vector<T>& values() { return mData; }
  const std::vector<T>& values() const { return mData; }

 private:
  glm::ivec3 mSize{0};
  std::vector<T> mData;
};

using ScalarGrid = Grid3<float>;
using FlagGrid = Grid3<std::uint8_t>;
using VectorGrid = Grid3<glm::vec3>;

}  // namespace plume
