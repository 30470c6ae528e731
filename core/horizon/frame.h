// What the horizon-based kernels (HBAO, GTAO, the visibility bitmask) read of a frame and how
// they step through it: the depth (full resolution, or with far samples on the depth MIP
// chain), the prepared normals, the camera, and the image-space step of a direction.
#pragma once

#include <cstddef>

#include "core/base/camera.h"
#include "core/base/depth_mip.h"
#include "core/base/image.h"
#include "core/base/working_memory.h"

namespace aolab {

/// What the horizon kernels read of a frame: depth with background as NaN (so every comparison
/// with it fails), prepared normals (3 floats per pixel), the size and the camera; HBAO marches
/// its directions over it and GTAO's slices theirs (SliceFrame, slice.h).
struct HorizonFrame {
  const float* depth;
  const float* normals;
  int width, height;
  CameraIntrinsics cam;
  /// With far samples on the depth MIP chain (mip_distance > 0): `depth` is the chain (its
  /// level 0 the frame), `mip` its layout and inv_mip_distance 1/q; else 0.
  DepthMipLayout mip = {};
  float inv_mip_distance = 0.0f;
};

/// The frame over `depth` (background as NaN) and prepared `normals`; with mip_distance q > 0
/// the depth MIP chain is appended to `depth` (build_depth_mip) for far samples.
HorizonFrame horizon_frame(Buffer<float>& depth, const Image& normals, const CameraIntrinsics& cam,
                           float mip_distance, int threads);

/// Where the sample at (sx, sy), `distance` pixels from P along its direction, reads its depth
/// in f.depth; with the MIP chain (f.inv_mip_distance > 0) the sample first snaps to its
/// level's pixel (sx, sy updated).
inline std::size_t horizon_sample_index(const HorizonFrame& f, float distance, int& sx, int& sy) {
  if (!(f.inv_mip_distance > 0.0f)) return std::size_t(sy) * std::size_t(f.width) + sx;
  const int level = depth_mip_level(distance * f.inv_mip_distance, f.mip.levels);
  const std::size_t index = depth_mip_index(f.mip, level, sx, sy);
  sx = depth_mip_pixel(sx, level, f.width), sy = depth_mip_pixel(sy, level, f.height);
  return index;
}

/// Image-space step (pixels) of direction (c, s) for a pixel at depth d: the eye-space
/// radius projected and split into N_s steps; image y points down, view y up.
inline void horizon_step(const CameraIntrinsics& cam, float radius, int steps, float depth, float c,
                         float s, float& step_x, float& step_y) {
  const float k = radius / (depth * float(steps));
  step_x = c * cam.fx * k;
  step_y = -s * cam.fy * k;
}

}  // namespace aolab
