// The SIMD kernel of the obscurance estimator (obscurance_estimator.h) that Alchemy AO and SAO
// share: obscurance_estimate on consecutive pixels of a row at once (Highway, every target,
// dispatched at run time; alchemy_simd.cpp). The scalar code stays the oracle it is tested
// against; docs/methods/alchemy.md, "SIMD kernel", says where the two differ.
#pragma once

#include <cstdint>
#include <vector>

#include "core/base/camera.h"
#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/methods/alchemy/obscurance_estimator.h"

namespace aolab {

/// SAO's z pyramid laid out for gathers: the coarse levels 1..count − 1 back to back in one
/// array (level 0 is the full-resolution depth itself), so that a lane's tap reads any coarse
/// level with one index, offset[m] + y·⌈W/2^m⌉ + x.
struct ObscuranceLevels {
  int count = 0;                     ///< levels 0..count − 1
  std::vector<float> depth;          ///< levels 1.. (NaN = background)
  std::vector<std::int32_t> source;  ///< per coarse texel, y·W + x of its pixel (empty: tap)
  std::vector<std::int32_t> offset;  ///< first texel of each level in `depth` (level 0: 0)
  float r_max_scale = 0.0f;          ///< r·max(fx, fy): h_i = α_i · r_max_scale / d (SAO §2.3)
  int log_max_offset = 0;            ///< q'
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
