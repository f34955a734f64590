#pragma once
/// \file linear_runs.h
/// The passes of trilinear semi-Lagrangian, MacCormack and BFECC advection fused per run of
/// eight samples (AVX2): sample, correct and limit in registers, one call per run instead of
/// one per step. Each gives what the generic passes of advection.cpp give, bit for bit.

#include "core/sample_points.h"

namespace plume {

/// Samples per run the kernels below take.
constexpr int kLinearRun = 8;

/// True when the kernels below may be called (the CPU has AVX2).
bool linearRunsAvailable();

/// out[m] = src at back point c+m (trilinear): the semi-Lagrangian step (Stam 1999).
void semiLagrangianRun(const ScalarGrid& src, const SamplePoints& back, std::size_t c, float* out);

/// MacCormack's correction (Selle et al. 2008 eq. 7 and the §4 limiter): with φ̄ = φ̂ at fore
/// point c+m, out[m] = φ̂[c+m] + ½(φ[c+m] - φ̄) clamped to the range of φ around back point c+m.
void macCormackRun(const ScalarGrid& phi, const ScalarGrid& hat, const SamplePoints& back,
                   const SamplePoints& fore, std::size_t c, float* out);

/// BFECC's corrected field (Kim et al. 2005): out[m] = φ[c+m] + ½(φ[c+m] - φ̂ at fore point c+m).
void bfeccCorrectionRun(const ScalarGrid& phi, const ScalarGrid& hat, const SamplePoints& fore,
                        std::size_t c, float* out);

/// BFECC's last step: out[m] = src at back point c+m, clamped to the range of φ around it.
void clampedRun(const ScalarGrid& src, const ScalarGrid& phi, const SamplePoints& back,
                std::size_t c, float* out);

}  // namespace plume
