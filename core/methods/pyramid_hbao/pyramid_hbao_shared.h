// What Pyramid HBAO's scalar code (pyramid_hbao.cpp) and its SIMD kernel (pyramid_hbao_simd.cpp)
// share: the largest image the SIMD kernel takes and its entry. Private to
// core/methods/pyramid_hbao/ (docs/architecture.md, "Two kernels per method").
#pragma once

#include "core/base/camera.h"
#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/methods/pyramid_hbao/gather_pyramid.h"
#include "core/methods/pyramid_hbao/pyramid_hbao.h"

namespace aolab {

/// Longest image side the SIMD kernel takes: below it, P's own texel on level l, ⌊x / K^l⌋,
/// is computed exactly in float (pyramid_hbao_simd.cpp). pyramid_hbao() runs the scalar code
/// for larger images.
constexpr int kPyramidHbaoSimdMaxSide = 1 << 22;

/// The SIMD kernel (pyramid_hbao_simd.cpp): the same algorithm as the scalar per-pixel code
/// for every setting, on consecutive pixels of a row at once. pyramid_hbao() runs it for
/// Kernel::Simd (without the final Gaussian, which it applies to either kernel's result).
/// `pyramid` holds the levels to march, `normals` the prepared normals (3 floats per pixel).
Image pyramid_hbao_simd(const GatherPyramid& pyramid, const float* normals,
                        const CameraIntrinsics& cam, const PyramidHbaoSettings& s, int threads,
                        Progress* progress);

}  // namespace aolab
