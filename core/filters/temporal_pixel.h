// What the accumulation step's scalar code (temporal.cpp) and its SIMD kernel
// (temporal_simd.cpp) share: one call's inputs and outputs, the per-pixel step (the oracle of
// the kernel and its path for the pixels the kernel leaves to it) and the kernel's entry.
#pragma once

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/filters/temporal.h"

namespace aolab {

/// One call of accumulate: what every pixel reads, and the images it writes (each pixel
/// writes its own four values and nothing else).
struct TemporalFrame {
  ConstImageView ao;
  const GBuffer& g;
  ConstImageView motion;
  const TemporalHistory& history;  ///< the previous frame's; empty on frame 0
  const TemporalSettings& settings;
  const Image& normals;  ///< this frame's prepared normals
  Image& accumulated;
  Image& disoccluded;
  Image& depth;   ///< the history's next depth: d, NaN on background
  Image& length;  ///< the history's next length: 0 on background, 1 disoccluded, else n + 1
};

/// The step at pixel (x, y), in double precision as docs/temporal.md writes it: the oracle.
void accumulate_pixel(const TemporalFrame& f, int x, int y);

/// Row y by the SIMD kernel: the same operations in the same order as accumulate_pixel, in
/// vectors of consecutive pixels, so the same bits; what it does not cover (the image's border
/// rows and columns, background, non-finite motion, a footprint leaving the image) it leaves
/// to accumulate_pixel.
void accumulate_row_simd(const TemporalFrame& f, int y);

}  // namespace aolab
