// The SIMD kernel (obscurance_simd.cpp) of the obscurance estimator (obscurance_estimator.h)
// that Alchemy AO and SAO share: obscurance_estimate on consecutive pixels of a row at once,
// and what it reads. The scalar code stays the oracle it is tested against;
// docs/methods/alchemy.md, "SIMD kernel", says where the two differ.
#pragma once

#include <bit>
#include <cstdint>
#include <vector>

#include "core/base/camera.h"
#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/horizon/obscurance_estimator.h"

namespace aolab {

/// SAO's z pyramid laid out for gathers: the coarse levels 1..count − 1 back to back in one
/// array (level 0 is the full-resolution depth itself), so that a lane's tap reads any coarse
/// level with one index, t = offset[m] + y·⌈W/2^m⌉ + x. A texel is its depth's bits, followed,
/// when the taps move to their source pixels, by that pixel's index y·W + x: the tap's second
/// read then falls in the cache line of its first.
struct ObscuranceLevels {
  int count = 0;                     ///< levels 0..count − 1
  int stride = 1;                    ///< int32 per texel: 1 (depth) or 2 (depth, source)
  Buffer<std::int32_t> texels;       ///< levels 1.., `stride` per texel; a working array
  std::vector<std::int32_t> offset;  ///< first texel of each level (level 0: 0)
  float r_max_scale = 0.0f;          ///< r·max(fx, fy): h_i = α_i · r_max_scale / d (SAO §2.3)
  int log_max_offset = 0;            ///< q'

  std::size_t size() const { return texels.size() / std::size_t(stride); }
  bool has_sources() const { return stride == 2; }
  /// Texel t's depth (NaN = background) and, with sources, its pixel y·W + x.
  float depth(std::size_t t) const { return std::bit_cast<float>(texels[t * std::size_t(stride)]); }
  std::int32_t source(std::size_t t) const { return texels[t * std::size_t(stride) + 1]; }
};

/// What the kernel reads and the settings it folds in.
struct ObscuranceSimdFrame {
  const float* depth;    ///< W × H, background = NaN (level 0)
  const float* normals;  ///< prepared, 3 per pixel
  int width, height;
  CameraIntrinsics cam;
  float radius;
  bool random_rotation;
  int seed;
  /// The bias distance in units of r, b/r = bias_per_depth · d + bias_constant (Alchemy:
  /// β·d/r; SAO: β).
  float bias_per_depth, bias_constant;
  const SpiralTaps* taps;
  const ObscuranceEstimator* estimator;
  /// SAO's pyramid, or null (Alchemy: every tap reads `depth`).
  const ObscuranceLevels* levels;
};

/// The raw estimate of every pixel (background 1), as obscurance_estimate gives it; rows in
/// tiles on `threads` threads, the same bits for any thread count.
Image obscurance_simd(const ObscuranceSimdFrame& frame, int threads, Progress* progress);

}  // namespace aolab
