#pragma once
/// \file byte_buffer.h
/// Little-endian byte buffers, the FNV-1a checksum and atomic file writes shared by Plume's
/// binary cache formats (DESIGN.md "io": versioned header, sizes checked on read, never trusted).

#include <cstdint>
#include <cstring>
#include <functional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace plume {

/// FNV-1a, 64 bit, over a byte range, continuing from `hash`.
std::uint64_t fnv1a64(const unsigned char* data, std::size_t size,
                      std::uint64_t hash = 0xcbf29ce484222325ull);

/// Appends little-endian values to a growing buffer.
class ByteWriter {
 public:
  void reserve(std::size_t n) { mBuf.reserve(n); }
  void bytes(const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    mBuf.insert(mBuf.end(), c, c + n);
  }
  template <typename T>
  void integer(T v) {
    for (std::size_t b = 0; b < sizeof(T); ++b)
      mBuf.push_back(static_cast<unsigned char>((static_cast<std::uint64_t>(v) >> (8 * b)) & 0xff));
  }
  /// `n` 32-bit floats starting at p.
  void floats(const float* p, std::size_t n);
  /// Appends the u64 FNV-1a 64 checksum of every byte so far (the trailer of Plume's files).
  void checksum() { integer<std::uint64_t>(fnv1a64(mBuf.data(), mBuf.size())); }
  std::vector<unsigned char>& buffer() { return mBuf; }
  const std::vector<unsigned char>& buffer() const { return mBuf; }

 private:
  std::vector<unsigned char> mBuf;
};

/// Reads little-endian values from a buffer; every read is bounds-checked and throws
/// std::runtime_error "<kind> '<path>' is truncated" past the end.
class ByteReader {
 public:
  ByteReader(const unsigned char* data, std::size_t size, std::string kind, std::string path)
      : mData(data), mSize(size), mKind(std::move(kind)), mPath(std::move(path)) {}
  void need(std::size_t n) const;
  template <typename T>
  T integer() {
    need(sizeof(T));
    std::uint64_t v = 0;
    for (std::size_t b = 0; b < sizeof(T); ++b) v |= std::uint64_t(mData[mPos + b]) << (8 * b);
    mPos += sizeof(T);
    return static_cast<T>(v);
  }
  std::string string(std::size_t n) {
    need(n);
    std::string s(reinterpret_cast<const char*>(mData + mPos), n);
    mPos += n;
    return s;
  }
  /// `n` 32-bit floats into out (n entries, already sized by the caller).
  void floats(float* out, std::size_t n);
  /// Reads a file header: `magicSize` magic bytes, then a u32 version that must be `version`.
  /// Throws std::runtime_error "<kind> '<path>' is not a Plume <kind> (bad magic)" or "... has
  /// version N; this build reads version M".
  void header(const char* magic, std::size_t magicSize, std::uint32_t version);
  /// Same, accepting any version in [oldest, newest]; returns the version found ("... has
  /// version N; this build reads version oldest-newest" otherwise).
  std::uint32_t header(const char* magic, std::size_t magicSize, std::uint32_t oldest,
                       std::uint32_t newest);
  /// Whether the whole buffer ends with the u64 FNV-1a 64 checksum of the bytes before it.
  bool checksumMatches() const;
  void bytes(void* out, std::size_t n) {
    need(n);
    if (n) std::memcpy(out, mData + mPos, n);  // out may be null for n == 0 (an empty vector)
    mPos += n;
  }
  std::size_t position() const { return mPos; }
  std::size_t remaining() const { return mSize - mPos; }

 private:
  const unsigned char* mData;
  std::size_t mSize;
  std::string mKind, mPath;
  std::size_t mPos = 0;
};

/// Why a write failed, from its errno: "the disk is full (No space left on device)" for
/// ENOSPC and EDQUOT, "the file size limit is reached (File too large)" for EFBIG (RLIMIT_FSIZE,
/// the file system's largest file), else strerror; "a short write" when errno is 0.
std::string writeFailure(int err);

/// The errno a failed write of `path` most likely met when the one at hand is lost (0: the
/// stream's writes may have run on another thread, whose errno is its own): EFBIG when the file
/// reached the process's file size limit (RLIMIT_FSIZE), ENOSPC when the file system has no
/// block left for it, else 0. Call before removing the partial file.
int writeFailureCause(const std::string& path, int err);

/// Writes `bytes` to `path` atomically: to "<path>.tmp", then rename. Throws std::runtime_error
/// "<kind> '<path>' cannot be written ..." on failure, leaving no temporary file behind.
void writeFileAtomic(const std::string& path, const std::vector<unsigned char>& bytes,
                     const std::string& kind);

/// The same for a file written piece by piece: write(out) writes the content to the binary
/// stream `out` (large files need no copy in memory).
void writeFileAtomic(const std::string& path, const std::string& kind,
                     const std::function<void(std::ostream&)>& write);

/// The whole file at `path`, after checking that its size is between minSize and maxSize bytes.
/// Throws std::runtime_error "<kind> '<path>' ..." when it cannot be opened or read, or when its
/// size is out of range (nothing is allocated from an untrusted size).
std::vector<unsigned char> readFileChecked(const std::string& path, std::size_t minSize,
                                           std::size_t maxSize, const std::string& kind);

}  // namespace plume
