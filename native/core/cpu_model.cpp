/// \file cpu_model.cpp
/// The x86 CPU model that `__builtin_cpu_supports` and function multi-versioning
/// (PLUME_AVX2_CLONES) read: `__cpu_model` and `__cpu_indicator_init`, the interface libgcc and
/// LLVM's compiler-rt share. Built only into the portable modules (cmake/portable): zig's
/// compiler runtime does not carry them, and an undefined one would be looked up in Blender's
/// process at load time. Hidden, so it never meets libgcc's copy.
///
/// Only the feature bits are filled (vendor, type and subtype stay 0, "other"): Plume asks for
/// instruction sets, never for a CPU family. The bit numbers are the shared ProcessorFeatures
/// enumeration (compiler-rt's cpu_model/x86.c, GCC's common/config/i386/i386-cpuinfo.h).

#include <cpuid.h>

namespace {

enum Feature : unsigned {
  kCmov = 0, kPopcnt = 2, kSse = 3, kSse2 = 4, kSse3 = 5, kSsse3 = 6, kSse41 = 7, kSse42 = 8,
  kAvx = 9, kAvx2 = 10, kFma = 14,
};

/// XCR0 bits 1 and 2: the operating system saves SSE and AVX state on a context switch.
bool osSavesAvx() {
  unsigned lo, hi;
  __asm__ volatile("xgetbv" : "=a"(lo), "=d"(hi) : "c"(0));
  return (lo & 6u) == 6u;
}

}  // namespace

extern "C" {

struct PlumeProcessorModel {
  unsigned vendor, type, subtype;
  unsigned features[1];
};

__attribute__((visibility("hidden"))) PlumeProcessorModel __cpu_model;
/// Features 32 and up (AVX-512 and later): never asked for, kept at 0.
__attribute__((visibility("hidden"))) unsigned __cpu_features2[3];

/// Fills __cpu_model once; called by ifunc resolvers (before any constructor) and by
/// __builtin_cpu_init.
__attribute__((visibility("hidden"))) int __cpu_indicator_init(void) {
  if (__cpu_model.features[0] != 0) return 0;
  unsigned a, b, c, d, bits = 1u << kCmov;  // every x86-64 has CMOV
  if (__get_cpuid(1, &a, &b, &c, &d)) {
    if (d & (1u << 25)) bits |= 1u << kSse;
    if (d & (1u << 26)) bits |= 1u << kSse2;
    if (c & (1u << 0)) bits |= 1u << kSse3;
    if (c & (1u << 9)) bits |= 1u << kSsse3;
    if (c & (1u << 19)) bits |= 1u << kSse41;
    if (c & (1u << 20)) bits |= 1u << kSse42;
    if (c & (1u << 23)) bits |= 1u << kPopcnt;
    const bool avx = (c & (1u << 28)) && (c & (1u << 27)) && osSavesAvx();  // AVX + OSXSAVE
    if (avx) {
      bits |= 1u << kAvx;
      if (c & (1u << 12)) bits |= 1u << kFma;
      if (__get_cpuid_count(7, 0, &a, &b, &c, &d) && (b & (1u << 5))) bits |= 1u << kAvx2;
    }
  }
  __cpu_model.features[0] = bits;
  return 0;
}

}  // extern "C"
