#pragma once
/// \file bench_memory.h
/// Process CPU time and resident memory for the benchmarks (Linux /proc and getrusage).

#include <sys/resource.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

namespace plume::bench {

/// CPU seconds of every thread of the process so far (user + system).
inline double processCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

/// A field of /proc/self/status in MB: "VmRSS:" (resident now) or "VmHWM:" (peak resident).
inline double statusMb(const char* key) {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind(key, 0) == 0) return std::stod(line.substr(std::strlen(key))) / 1024.0;
  return 0.0;
}

/// Resets the peak resident set (VmHWM) to the current one (Linux >= 4.0), so that the next
/// statusMb("VmHWM:") is the peak of what runs in between.
inline void resetPeakRss() {
  if (std::FILE* f = std::fopen("/proc/self/clear_refs", "w")) {
    std::fputs("5", f);
    std::fclose(f);
  }
}

}  // namespace plume::bench
