// What LSAO's scalar code (lsao.cpp) and its SIMD kernel (lsao_simd.cpp) share: the settings
// check both run and the SIMD kernel's entries, the sweep and the gather apart for the tests
// and benchmarks. Private to core/methods/lsao/ and its tests (docs/architecture.md, "Two
// kernels per method").
#pragma once

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/methods/lsao/lsao.h"
#include "core/methods/registry.h"

namespace aolab {

/// Throws std::invalid_argument unless `s` is valid (ranges, and K = 8n for aligned sets).
void validate_lsao_settings(const LsaoSettings& s);

/// lsao() with Kernel::Simd: lsao_sweep_simd then lsao_gather_simd, the depth prepared once.
Image lsao_simd_kernel(const GBuffer& g, const LsaoSettings& s, const RunOptions& options = {});

/// The SIMD sweep (lsao_simd.cpp, Kernel::Simd): Algorithm 1 on a vector of parallel lines at
/// once; lsao_sweep's buffer within the tolerance of tests/cpp/methods/lsao/lsao_simd_test.cpp
/// (the same samples and depths; the values rounded differently).
/// keep_buffer = false leaves `buffer` empty where lsao_gather_simd reads texel_runs instead.
LsaoSweep lsao_sweep_simd(const GBuffer& g, const LsaoSettings& s, const RunOptions& options = {},
                          bool keep_buffer = true);

/// The SIMD gather (lsao_simd.cpp, Kernel::Simd): lsao_gather's result within the tolerance
/// of tests/cpp/methods/lsao/lsao_simd_test.cpp (it picks the same samples; the weighted sums
/// are rounded in float). It reads sweep.texel_runs, which lsao_sweep_simd makes for aligned
/// sets with sampling = snap; otherwise it is lsao_gather.
Image lsao_gather_simd(const GBuffer& g, const LsaoSettings& s, const LsaoSweep& sweep,
                       const RunOptions& options = {});

}  // namespace aolab
