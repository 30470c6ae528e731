// What Crytek SSAO's scalar code (crytek_ssao.cpp) and its SIMD kernel (crytek_ssao_simd.cpp)
// share: the SIMD kernel's entry. Private to core/methods/crytek_ssao/ (docs/architecture.md, "Two
// kernels per method").
#pragma once

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/methods/crytek_ssao/crytek_ssao.h"

namespace aolab {

/// The SIMD kernel (crytek_ssao_simd.cpp): the scalar per-pixel code's algorithm for every
/// setting on consecutive pixels of a row at once. It reads the G-buffer's depth as it is
/// (background tested where it is read, not replaced by NaN); `normals` are the prepared
/// normals (3 per pixel), null unless the hemisphere variant; `kernel` is
/// crytek_ssao_kernel()'s and `tile` the 16 reflection vectors of `rotation = tiled4x4`
/// (pixel (x, y) reads tile[(x & 3) + 4 (y & 3)]). crytek_ssao() runs it for Kernel::Simd.
Image crytek_ssao_simd(const GBuffer& g, const float* normals, const CrytekSsaoSettings& s,
                       const std::vector<glm::vec3>& kernel, const glm::vec3 (&tile)[16],
                       int threads, Progress* progress);

}  // namespace aolab
