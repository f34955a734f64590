/// \file fuzz_common.cpp
/// Temporary input files and the message checks of the fuzz targets.

#include "fuzz_common.h"

#include "io/byte_buffer.h"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <sys/stat.h>
#include <unistd.h>

namespace plume::fuzz {

TempInput::TempInput(const std::string& target, const std::string& extension) {
  struct stat st;
  std::string dir = "/dev/shm";
  if (stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode) || access(dir.c_str(), W_OK) != 0) {
    const char* tmp = std::getenv("TMPDIR");
    dir = tmp && *tmp ? tmp : "/tmp";
  }
  mPath = dir + "/plume_fuzz_" + target + "_" + std::to_string(getpid()) + extension;
}

TempInput::~TempInput() { std::remove(mPath.c_str()); }

const std::string& TempInput::write(const std::uint8_t* data, std::size_t size) {
  std::ofstream out(mPath, std::ios::binary | std::ios::trunc);
  if (size) out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  out.close();
  if (!out) finding("cannot write the temporary input " + mPath);
  return mPath;
}

bool isUtf8(const std::string& text) {
  const auto* s = reinterpret_cast<const unsigned char*>(text.data());
  const std::size_t n = text.size();
  for (std::size_t i = 0; i < n;) {
    const unsigned c = s[i];
    std::size_t len;
    unsigned cp;
    if (c < 0x80) {
      ++i;
      continue;
    } else if ((c & 0xe0) == 0xc0) {
      len = 2, cp = c & 0x1f;
    } else if ((c & 0xf0) == 0xe0) {
      len = 3, cp = c & 0x0f;
    } else if ((c & 0xf8) == 0xf0) {
      len = 4, cp = c & 0x07;
    } else {
      return false;
    }
    if (i + len > n) return false;
    for (std::size_t k = 1; k < len; ++k) {
      if ((s[i + k] & 0xc0) != 0x80) return false;
      cp = (cp << 6) | (s[i + k] & 0x3f);
    }
    const unsigned least[5] = {0, 0, 0x80, 0x800, 0x10000};
    if (cp < least[len] || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff)) return false;
    i += len;
  }
  return true;
}

void finding(const std::string& what) {
  std::fprintf(stderr, "plume fuzz finding: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

void checkMessage(const std::string& message, const std::string& path) {
  static const bool verbose = std::getenv("PLUME_FUZZ_VERBOSE") != nullptr;
  if (verbose) std::fprintf(stderr, "refused: %s\n", message.c_str());
  if (!isUtf8(message)) finding("error message is not valid UTF-8: " + message);
  if (message.find(path) == std::string::npos)
    finding("error message does not name the file '" + path + "': " + message);
}

void resignTrailer(std::uint8_t* data, std::size_t size) {
  if (size < 8) return;
  const std::uint64_t sum = fnv1a64(data, size - 8);
  for (int b = 0; b < 8; ++b)
    data[size - 8 + std::size_t(b)] = std::uint8_t((sum >> (8 * b)) & 0xff);
}

}  // namespace plume::fuzz
