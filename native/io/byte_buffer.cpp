#include "io/byte_buffer.h"

#include <cerrno>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>

namespace plume {
namespace {

bool hostIsLittleEndian() {
  const std::uint32_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

}  // namespace

std::uint64_t fnv1a64(const unsigned char* data, std::size_t size, std::uint64_t hash) {
  for (std::size_t n = 0; n < size; ++n) {
    hash ^= data[n];
    hash *= 0x100000001b3ull;
  }
  return hash;
}

void ByteWriter::floats(const float* p, std::size_t n) {
  const std::size_t start = mBuf.size();
  mBuf.resize(start + 4 * n);
  if (hostIsLittleEndian()) {
    if (n) std::memcpy(mBuf.data() + start, p, 4 * n);
    return;
  }
  for (std::size_t m = 0; m < n; ++m) {
    std::uint32_t u;
    std::memcpy(&u, p + m, 4);
    for (int b = 0; b < 4; ++b) mBuf[start + 4 * m + std::size_t(b)] = (u >> (8 * b)) & 0xff;
  }
}

void ByteReader::need(std::size_t n) const {
  if (n > mSize - mPos) throw std::runtime_error(mKind + " '" + mPath + "' is truncated");
}

void ByteReader::floats(float* out, std::size_t n) {
  if (n > (mSize - mPos) / 4) throw std::runtime_error(mKind + " '" + mPath + "' is truncated");
  if (hostIsLittleEndian()) {
    if (n) std::memcpy(out, mData + mPos, 4 * n);
  } else {
    for (std::size_t m = 0; m < n; ++m) {
      std::uint32_t u = 0;
      for (int b = 0; b < 4; ++b) u |= std::uint32_t(mData[mPos + 4 * m + std::size_t(b)]) << (8 * b);
      std::memcpy(out + m, &u, 4);
    }
  }
  mPos += 4 * n;
}

void ByteReader::header(const char* magic, std::size_t magicSize, std::uint32_t version) {
  header(magic, magicSize, version, version);
}

std::uint32_t ByteReader::header(const char* magic, std::size_t magicSize, std::uint32_t oldest,
                                 std::uint32_t newest) {
  if (string(magicSize) != std::string(magic, magicSize))
    throw std::runtime_error(mKind + " '" + mPath + "' is not a Plume " + mKind + " (bad magic)");
  const auto found = integer<std::uint32_t>();
  if (found < oldest || found > newest)
    throw std::runtime_error(mKind + " '" + mPath + "' has version " + std::to_string(found) +
                             "; this build reads version " +
                             (oldest == newest ? std::to_string(newest)
                                               : std::to_string(oldest) + "-" +
                                                     std::to_string(newest)));
  return found;
}

bool ByteReader::checksumMatches() const {
  if (mSize < 8) return false;
  std::uint64_t stored = 0;
  for (std::size_t b = 0; b < 8; ++b) stored |= std::uint64_t(mData[mSize - 8 + b]) << (8 * b);
  return fnv1a64(mData, mSize - 8) == stored;
}

std::string writeFailure(int err) {
  if (err == 0) return "a short write";
  const std::string text = std::strerror(err);
  if (err == ENOSPC || err == EDQUOT) return "the disk is full (" + text + ")";
  if (err == EFBIG) return "the file size limit is reached (" + text + ")";
  return text;
}

int writeFailureCause(const std::string& path, int err) {
  if (err != 0) return err;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return 0;
  struct rlimit limit {};
  if (::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY &&
      static_cast<rlim_t>(st.st_size) >= limit.rlim_cur)
    return EFBIG;
  struct statvfs fs {};
  // "No block left": less free than one 64 KiB stream buffer for an unprivileged writer.
  if (::statvfs(path.c_str(), &fs) == 0 &&
      static_cast<unsigned long long>(fs.f_bavail) * fs.f_frsize < (64ull << 10))
    return ENOSPC;
  return 0;
}

void writeFileAtomic(const std::string& path, const std::vector<unsigned char>& bytes,
                     const std::string& kind) {
  writeFileAtomic(path, kind, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  });
}

void writeFileAtomic(const std::string& path, const std::string& kind,
                     const std::function<void(std::ostream&)>& write) {
  const std::string tmp = path + ".tmp";
  bool ok = false;
  errno = 0;
  int err = 0;
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (out) {
      write(out);
      out.flush();
      ok = bool(out);
      if (!ok) err = errno;  // the failed write(2)'s
      out.close();
      if (ok && out.fail()) err = errno;
      ok = ok && !out.fail();
    } else {
      err = errno;
    }
  }
  if (!ok) {
    err = writeFailureCause(tmp, err);  // writes on a worker thread leave errno there
    std::remove(tmp.c_str());  // no half file: the previous one, if any, stays
    throw std::runtime_error(kind + " '" + path + "' cannot be written: " + writeFailure(err));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error(kind + " '" + path + "' cannot be written: renaming the temporary file '" +
                             tmp + "' failed");
  }
}

std::vector<unsigned char> readFileChecked(const std::string& path, std::size_t minSize,
                                           std::size_t maxSize, const std::string& kind) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error(kind + " '" + path + "' cannot be opened");
  const std::streamoff size = in.tellg();
  if (size < 0) throw std::runtime_error(kind + " '" + path + "' cannot be read");
  if (std::size_t(size) < minSize)
    throw std::runtime_error(kind + " '" + path + "' is truncated (shorter than its header)");
  if (std::size_t(size) > maxSize)
    throw std::runtime_error(kind + " '" + path + "' is too large (" + std::to_string(size) +
                             " bytes)");
  std::vector<unsigned char> buf(static_cast<std::size_t>(size));
  in.seekg(0);
  if (size > 0 && !in.read(reinterpret_cast<char*>(buf.data()), size))
    throw std::runtime_error(kind + " '" + path + "' cannot be read");
  return buf;
}

}  // namespace plume
