// What VAO++'s scalar code (vao_pp.cpp) and its SIMD kernels (vao_pp_simd.cpp,
// bilateral_simd.cpp) share: what the passes of one run read and count, the SIMD pre-pass and
// occlusion pass, and the cross-bilateral filter in vectors. Private to core/methods/vao_pp/
// and its tests (docs/architecture.md, "Two kernels per method").
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/methods/vao_pp/vao_pp.h"
#include "core/volumetric/pipes.h"
#include "core/volumetric/pipes_simd.h"

namespace aolab {

namespace vao_pp_detail {

/// What the passes of one run share (the sample sets apart: each kernel has its own form).
struct Pass {
  const GBuffer& g;
  const VaoPpSettings& s;
  const VaoFrame& frame;
  VaoPixelOptions po;  // without colour bleeding (the pre-pass)
  VaoPpCulling culling;
  int threads;
  Progress* progress;

  bool geometry(int x, int y) const {
    const float d = frame.depth[std::size_t(y) * frame.width + x];
    return d == d;
  }
};

/// VaoPpStats as the threads add to it.
struct Counters {
  std::atomic<std::int64_t> prepass_pixels{0}, pixels{0}, culled{0}, samples{0};
};

/// The SIMD kernel's passes 0 and 1 (vao_pp_simd.cpp): the culling pre-pass (§4.2) and the
/// occlusion pass (§3), vao_simd_span on rows; the scalar passes' results within the
/// tolerances of tests/cpp/methods/vao/vao_simd_test.cpp.
Image cull_prepass_simd(const Pass& r, const VaoSimdSets& sets, Counters& counters);
Image occlusion_pass_simd(const Pass& r, const VaoSimdSets& sets, const Image& low,
                          Counters& counters);

}  // namespace vao_pp_detail

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
