#pragma once
/// \file cpu_features.h
/// Run-time choice of instruction sets. The build targets x86-64-v2 (SSE4.2); the hot kernels
/// also exist as AVX2 code, chosen per process where the CPU has it. No FMA anywhere: a fused
/// multiply-add rounds once where the reference form rounds twice, and every variant must give
/// the same values bit for bit (tests compare them).

namespace plume {

/// True when this CPU runs AVX2 (asked once per process).
bool hasAvx2();

}  // namespace plume

#if defined(__x86_64__) && defined(__GNUC__) && !defined(PLUME_NO_AVX2) && \
    (!defined(__clang__) || __clang_major__ >= 16)
/// A function compiled twice, for AVX2 and for the build's baseline, the loader picking one
/// (function multi-versioning: GCC, and clang 16+ as in the portable build; the fuzzers' clang
/// 14 builds the baseline only). For row kernels: a call per row, the loop inside vectorized
/// twice as wide; "avx2" does not enable FMA, so the results are the same bit for bit.
#define PLUME_AVX2_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define PLUME_AVX2_CLONES
#endif
