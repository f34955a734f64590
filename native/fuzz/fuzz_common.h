#pragma once
/// \file fuzz_common.h
/// What every fuzz target of Plume's readers shares (README.md "Reliability"): the input
/// written to a per-process temporary file (the readers take paths), and the property a reader
/// must keep on any bytes: it returns, or it throws its documented exception type with a clean
/// UTF-8 message that names the file. Anything else (another exception type, a message without
/// the path or with broken UTF-8) aborts, so libFuzzer and the replay ctest report it like a
/// crash.

#include <cstddef>
#include <cstdint>
#include <exception>
#include <stdexcept>
#include <string>

namespace plume::fuzz {

/// A file in /dev/shm (else the temporary directory) named after the target and the process,
/// with the reader's extension (".vdb" for OpenVDB), rewritten for every input and removed at exit.
class TempInput {
 public:
  explicit TempInput(const std::string& target, const std::string& extension = ".bin");
  ~TempInput();
  TempInput(const TempInput&) = delete;
  TempInput& operator=(const TempInput&) = delete;
  /// Writes the bytes (truncating) and returns the path.
  const std::string& write(const std::uint8_t* data, std::size_t size);
  const std::string& path() const { return mPath; }

 private:
  std::string mPath;
};

/// Whether `text` is well-formed UTF-8 (no overlong forms, surrogates or code points > U+10FFFF).
bool isUtf8(const std::string& text);

/// Aborts (after printing what and why) unless `message` names `path` and is clean UTF-8.
/// With PLUME_FUZZ_VERBOSE set in the environment, prints every message (replaying by hand).
void checkMessage(const std::string& message, const std::string& path);

/// Prints `what` and aborts: a finding.
[[noreturn]] void finding(const std::string& what);

/// Runs `read`; a std::runtime_error whose message passes checkMessage is the clean refusal, any
/// other exception is a finding. Returns whether `read` returned normally.
template <typename Read>
bool expectClean(const std::string& path, Read&& read) {
  try {
    read();
    return true;
  } catch (const std::runtime_error& e) {
    checkMessage(e.what(), path);
  } catch (const std::exception& e) {
    finding(std::string("unexpected exception type (not std::runtime_error): ") + e.what());
  } catch (...) {
    finding("unexpected exception of a non-std type");
  }
  return false;
}

/// Writes the u64 FNV-1a 64 of data[0, size - 8) into the last 8 bytes (the trailer of Plume's
/// state, tracer state, streak and toon files); nothing when size < 8.
void resignTrailer(std::uint8_t* data, std::size_t size);

}  // namespace plume::fuzz

/// Checksums (the choice, explained): every Plume format ends in (or, for pathlines, holds) an
/// FNV-1a 64 checksum that the reader verifies before it parses anything past the sizes. A blind
/// mutation almost never keeps it valid (1 in 2^64), so plain libFuzzer would test little more
/// than the checksum comparison. A dictionary cannot help (the checksum depends on every byte).
/// So each target under libFuzzer has a custom mutator: libFuzzer's own mutation, then, for half
/// of the mutants (chosen by the seed libFuzzer passes, so runs are reproducible), the
/// checksum(s) recomputed by `RESIGN(data, size)`. The other half keeps testing the checksum
/// path. Crash inputs saved by libFuzzer are the resigned bytes, so replay needs no mutator.
/// Only the libFuzzer build (PLUME_FUZZ_LIBFUZZER) defines it: the gcc replay build has no
/// LLVMFuzzerMutate.
#ifdef PLUME_FUZZ_LIBFUZZER
extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t maxSize);
#define PLUME_FUZZ_RESIGNING_MUTATOR(RESIGN)                                                  \
  extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size,        \
                                                 std::size_t maxSize, unsigned int seed) {    \
    const std::size_t n = LLVMFuzzerMutate(data, size, maxSize);                              \
    if (seed & 1u) RESIGN(data, n);                                                           \
    return n;                                                                                 \
  }
#else
#define PLUME_FUZZ_RESIGNING_MUTATOR(RESIGN)
#endif
