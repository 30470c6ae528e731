// What VAO++'s scalar code (vao_pp.cpp) and its SIMD kernels (bilateral_simd.cpp) share: the
// cross-bilateral filter in vectors. Private to core/methods/vao_pp/ and its tests
// (docs/architecture.md, "Two kernels per method").
#pragma once

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/parallel.h"

namespace aolab {

/// cross_bilateral_filter (bilateral.h) by the SIMD kernel (bilateral_simd.cpp): the same taps in
/// the same order, the sums by fused multiply-adds, each channel on its own (so a channel's result
/// does not depend on the others').
Image cross_bilateral_filter_simd(ConstImageView image, const GBuffer& g, int taps, float sigma,
                                  float depth_threshold, int threads = 0,
                                  Progress* progress = nullptr);
/// The same with g's depth given as depth_with_background_as_nan made it (the size of image).
Image cross_bilateral_filter_simd(ConstImageView image, const float* depth, int taps, float sigma,
                                  float depth_threshold, int threads = 0,
                                  Progress* progress = nullptr);

}  // namespace aolab
