#pragma once
/// \file vdb_cursor.h
/// Bounded reads from the bytes of a VDB file (vdb_guard.h): every read is checked against the
/// end of the range before it happens, as OpenVDB's own reader does not.

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

namespace plume {

/// Reads host-endian values (as OpenVDB does) from bytes [begin, end) of a buffer; throws
/// std::runtime_error "truncated: <what> needs N bytes at byte P, K left" past the end.
class VdbCursor {
 public:
  VdbCursor(const unsigned char* data, std::size_t begin, std::size_t end)
      : mData(data), mPos(begin), mEnd(end) {}

  void need(std::size_t n, const char* what) const {
    if (n > mEnd - mPos)
      throw std::runtime_error("truncated: " + std::string(what) + " needs " + std::to_string(n) +
                               " bytes at byte " + std::to_string(mPos) + ", " +
                               std::to_string(mEnd - mPos) + " left");
  }
  template <typename T>
  T pod(const char* what) {
    need(sizeof(T), what);
    T v;
    std::memcpy(&v, mData + mPos, sizeof(T));
    mPos += sizeof(T);
    return v;
  }
  /// A string stored as a u32 length and its bytes (OpenVDB's readString).
  std::string string(const char* what) {
    const std::uint32_t n = pod<std::uint32_t>(what);
    need(n, what);
    std::string s(reinterpret_cast<const char*>(mData + mPos), n);
    mPos += n;
    return s;
  }
  /// Skips n bytes; returns the position of the first.
  std::size_t skip(std::size_t n, const char* what) {
    need(n, what);
    mPos += n;
    return mPos - n;
  }
  const unsigned char* at(std::size_t pos) const { return mData + pos; }
  std::size_t position() const { return mPos; }
  std::size_t remaining() const { return mEnd - mPos; }

 private:
  const unsigned char* mData;
  std::size_t mPos;
  std::size_t mEnd;
};

}  // namespace plume
