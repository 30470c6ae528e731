// What SAO's scalar code (sao.cpp, sao_blur.cpp) and its SIMD kernel (sao_simd.cpp) share:
// the z pyramid laid out for the SIMD estimator SAO shares with Alchemy AO
// (core/horizon/obscurance_simd.h) and the bilateral reconstruction in vectors. sao() runs them for
// Kernel::Simd; the scalar code is the oracle they are tested against. Private to core/methods/sao/
// and its tests (docs/architecture.md, "Two kernels per method").
#pragma once

#include <span>

#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/horizon/obscurance_simd.h"
#include "core/methods/sao/sao.h"
#include "core/methods/sao/sao_blur.h"

namespace aolab {

/// sao_z_pyramid's levels 1..max_level in one array (level 0 is `depth` itself), with the
/// source pixel of every coarse texel when `with_sources` (SaoTapPosition::Source). Texel for
/// texel the same depths and sources as sao_z_pyramid. Throws std::invalid_argument when the
/// coarse levels hold more than 2^31 − 1 texels (the gathers' indices are 32-bit) or the image
/// has 2^22 rows or more (the kernel's float quotient for a source's row).
ObscuranceLevels sao_levels_for_simd(std::span<const float> depth, int width, int height,
                                     int max_level, SaoGrid grid, bool with_sources, int threads);

/// sao_bilateral_filter in vectors, then every pixel clamped to [0, 1] (sao()'s last step).
void sao_bilateral_filter_simd(Image& ao, std::span<const float> depth, const SaoBlurParams& params,
                               int threads, Progress* progress);

}  // namespace aolab
