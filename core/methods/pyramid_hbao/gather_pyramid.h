// The depth pyramid of Pyramid HBAO (depth_pyramid.h) laid out for the SIMD kernel's gathers
// (pyramid_hbao_simd.cpp): the same texels, bit for bit, in arrays instead of structures.
//
// - Every level keeps its depths in one array, so that a gather of a read's depth loads one
//   float and the reads of a tile stay in the core's L1 (level 0 is 4 bytes per pixel, not
//   DepthPyramid's 12).
// - A texel's centroid is implied where its footprint is whole — the footprint's centre
//   K^l·(X + ½, Y + ½) — and the depth of a texel whose centroid is elsewhere (the image
//   border or background cut its footprint) has its sign bit set; its centroid is then in
//   the arrays cx, cy. Level 0's centroids are always the pixel centres and have no arrays.
// - Built straight from the G-buffer, by DepthPyramid's rule and in its order of summation, so
//   each texel equals DepthPyramid's (tested); it does not build DepthPyramid.
#pragma once

#include <cstddef>
#include <vector>

#include "core/base/gbuffer.h"

namespace aolab {

/// One level, as the kernel gathers it. Texel (X, Y) is at [(Y + 1)·stride + X + 1] of each
/// array: a border of one background texel (NaN) surrounds the level, so that a read that
/// rounding puts just outside the image reads background instead of memory it does not own.
struct GatherPyramidLevel {
  int width = 0, height = 0;
  int stride = 0;  ///< width + 2
  int scale = 1;   ///< K^l
  /// Mean depth: NaN for background; negative (the mean's negation) where the centroid is
  /// not the footprint's centre.
  const float* depth = nullptr;
  /// The centroids (levels ≥ 1; nullptr on level 0), in full-resolution pixels.
  const float* cx = nullptr;
  const float* cy = nullptr;

  std::size_t at(int x, int y) const {
    return std::size_t(y + 1) * std::size_t(stride) + std::size_t(x + 1);
  }
};

class GatherPyramid {
 public:
  /// As DepthPyramid(g, reduction, levels, threads): the G-buffer's depth with background as
  /// NaN, and `levels` levels (0: down to 1×1). Throws as DepthPyramid does.
  GatherPyramid(const GBuffer& g, int reduction, int levels = 0, int threads = 0);

  int levels() const { return int(levels_.size()); }
  const GatherPyramidLevel& level(int l) const { return levels_.at(std::size_t(l)); }
  const GatherPyramidLevel* data() const { return levels_.data(); }

 private:
  struct Arrays {  // working arrays (working_memory.h)
    Buffer<float> depth, cx, cy;
  };
  std::vector<GatherPyramidLevel> levels_;
  std::vector<Arrays> storage_;
};

}  // namespace aolab
