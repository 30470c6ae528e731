// The slice set-up of GTAO's slice formulation (Jimenez, Wu, Pesce, Jarabo 2016, §4), shared
// by GTAO and the visibility bitmask (Therrien, Levesque, Gilet 2023, which keeps GTAO's slices
// and replaces its two horizon angles by a bitmask): the per-pixel view vector, the slice plane
// through it, the normal projected onto that plane (eq. 8's |proj n| and angle n), the march
// of one side's samples along the slice's screen direction (HBAO's step, jitter and image
// rules) and the per-sample tangent-plane test that keeps open planes exactly unoccluded.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <glm/geometric.hpp>
#include <limits>
#include <vector>

#include "core/base/camera.h"
#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/base/run_options.h"
#include "core/horizon/directions.h"
#include "core/horizon/frame.h"
#include "core/horizon/receiver.h"
#include "core/sampling/random.h"

namespace aolab {

/// The view-space inputs a slice method marches over: HBAO's, depth with background as NaN (so
/// every test on it fails) and the prepared normals, 3 per pixel.
using SliceFrame = HorizonFrame;

/// One slice of one pixel: the plane through P spanned by the view vector v and the
/// back-projected screen direction (the plane through the camera that holds the screen line).
struct SliceGeometry {
  glm::vec3 axis;        ///< unit normal of the slice plane
  float length;          ///< |proj n|, the eq. 8 weight
  double n;              ///< signed angle from v to proj n, towards side 0
  double cos_n, sin_n;   ///< of n
  float low[2];          ///< horizon cosine of the tangent on side 0 (+ω) and side 1 (−ω)
  float step_x, step_y;  ///< image step of side 0 in pixels
};

/// The true per-pixel view vector, from P towards the camera: −P/|P| = −r0/|r0|.
inline glm::vec3 slice_view_vector(const HorizonReceiver& p) {
  return glm::normalize(glm::vec3(-p.ox * p.inv_fx, p.oy * p.inv_fy, 1.0f));
}

/// The slice of screen direction (c, s) = (cos φ, sin φ) for receiver p with view vector v.
inline SliceGeometry make_slice_geometry(const CameraIntrinsics& cam, float radius, int steps,
                                         const HorizonReceiver& p, const glm::vec3& v, float c,
                                         float s) {
  SliceGeometry sl;
  // Moving along the screen direction (c·fx, −s·fy) changes the normalised image
  // coordinates by (c, s): the slice plane holds v and (c, s, 0).
  const glm::vec3 dir(c, s, 0.0f);
  sl.axis = glm::normalize(glm::cross(dir, v));
  const glm::vec3 tangent = glm::cross(v, sl.axis);  // in the plane, ⊥ v, towards side 0
  const glm::vec3 projected = p.n - sl.axis * glm::dot(p.n, sl.axis);
  sl.length = glm::length(projected);
  const float along_v = std::max(0.0f, glm::dot(projected, v));  // prepared normals face v
  const float along_t = glm::dot(projected, tangent);
  sl.n = std::atan2(double(along_t), double(along_v));
  sl.cos_n = std::cos(sl.n);
  sl.sin_n = std::sin(sl.n);
  // The tangent directions n ± π/2 as cosines from v: cos(n + π/2) = −sin n on side 0,
  // cos(n − π/2) = sin n on side 1 (the lowest horizons the hemisphere clamp allows).
  const float sin_n = sl.length > 0.0f ? along_t / sl.length : 0.0f;
  sl.low[0] = -sin_n;
  sl.low[1] = sin_n;
  horizon_step(cam, radius, steps, p.d, c, s, sl.step_x, sl.step_y);
  return sl;
}

/// D = S − P for the sample on P's pixel + (qx, qy) at depth ds, without cancellation (HBAO's
/// form, docs/methods/hbao.md step 6).
inline glm::vec3 slice_sample_offset(const HorizonReceiver& p, float qx, float qy, float ds) {
  const float dd = ds - p.d;
  return {(qx * ds + p.ox * dd) * p.inv_fx, -(qy * ds + p.oy * dd) * p.inv_fy, -dd};
}

/// The march of one side (sign +1: side 0, −1: side 1) of a slice: `steps` samples at
/// P's pixel centre + sign·(i − jitter)·step, i = 1 … steps, each snapped to its texel.
/// Leaving the image ends the march; P's own texel and background texels are skipped.
/// visit(sx, sy, ds) is called for every other sample in order and returns false to stop.
template <class Visit>
void march_slice_side(const SliceFrame& f, const HorizonReceiver& p, const SliceGeometry& sl,
                      int steps, float jitter, int side, Visit&& visit) {
  const float sign = side == 0 ? 1.0f : -1.0f;
  // |step| in pixels, for the MIP level of far samples (no fused add: the SIMD kernel's bits).
  const float step_len = std::sqrt(sl.step_x * sl.step_x + sl.step_y * sl.step_y);
  for (int i = 1; i <= steps; ++i) {
    const float t = sign * (float(i) - jitter);
    const float sx_f = p.px + t * sl.step_x, sy_f = p.py + t * sl.step_y;
    // Leaving the image along a straight line is final; the test also rejects inf/NaN.
    if (!(sx_f >= 0.0f && sx_f < float(f.width) && sy_f >= 0.0f && sy_f < float(f.height))) break;
    int sx = int(sx_f), sy = int(sy_f);  // snap to the texel (its centre below)
    const std::size_t index = horizon_sample_index(f, (float(i) - jitter) * step_len, sx, sy);
    if (sx == p.x && sy == p.y) continue;
    const float ds = f.depth[index];
    if (!(ds == ds)) continue;  // background never occludes
    if (!visit(sx, sy, ds)) break;
  }
}

/// What a slice method needs of one geometry pixel: the receiver, the view vector, the jitter
/// of its samples, and the slices' screen directions rotated into dir_cos/dir_sin (random
/// streams 0: rotation, 1: jitter, so that GTAO and the bitmask march the same samples).
struct SlicePixel {
  HorizonReceiver p;
  glm::vec3 v;
  float jitter;
};

/// Sets up pixel (x, y); false for background (AO 1).
inline bool slice_pixel(const SliceFrame& f, const HorizonDirections& directions, int x, int y,
                        int seed, bool random_rotation, bool jitter, float* dir_cos, float* dir_sin,
                        SlicePixel& out) {
  const std::size_t idx = std::size_t(y) * f.width + x;
  const float d = f.depth[idx];
  if (!(d == d)) return false;  // background
  out.p = horizon_receiver(f.cam, x, y, d,
                           {f.normals[3 * idx], f.normals[3 * idx + 1], f.normals[3 * idx + 2]});
  out.v = slice_view_vector(out.p);
  const auto s = std::uint32_t(seed);
  const float rotation = random_rotation ? pixel_random(s, x, y, 0) : 0.0f;
  out.jitter = jitter ? pixel_random(s, x, y, 1) : 0.0f;
  // 2N directions over a full turn are N slices over a half turn followed by their opposites.
  directions.rotated(rotation, dir_cos, dir_sin);
  return true;
}

/// The frame loop of a slice method on a validated G-buffer: working copies of depth (background
/// as NaN) and prepared normals, the 2·`slices` directions over a full turn (N slices over a
/// half turn followed by their opposites), rows in parallel with progress and cancellation.
/// pixel(frame, directions, x, y, dir_cos, dir_sin) returns the pixel's AO; dir_cos and dir_sin
/// are per-thread scratch of 2·`slices` floats. With Kernel::Simd, simd(frame, threads,
/// progress) computes the image instead (the method's SIMD kernel, on the same working copies).
template <class Pixel, class Simd>
Image run_slice_method(const GBuffer& g, int slices, float mip_distance, const RunOptions& options,
                       Pixel&& pixel, Simd&& simd) {
  const int w = g.width(), h = g.height();
  const int threads = resolve_threads(options.threads);
  Buffer<float> depth = depth_with_background_as_nan(g, threads);
  const Image normals = prepared_normals(g, threads);
  const SliceFrame frame = horizon_frame(depth, normals, g.camera, mip_distance, threads);
  if (options.kernel == Kernel::Simd) return simd(frame, threads, options.progress);
  const HorizonDirections directions(2 * slices);
  return image_from_pixels(
      w, h, threads, options.progress, [&] { return std::vector<float>(4 * std::size_t(slices)); },
      [&](std::vector<float>& dirs, int x, int y) {
        return pixel(frame, directions, x, y, dirs.data(), dirs.data() + 2 * slices);
      });
}

/// run_slice_method for a method with no SIMD kernel: the scalar loop for either kernel.
template <class Pixel>
Image run_slice_method(const GBuffer& g, int slices, const RunOptions& options, Pixel&& pixel) {
  RunOptions scalar = options;
  scalar.kernel = Kernel::Scalar;
  return run_slice_method(g, slices, 0.0f, scalar, pixel, [](const SliceFrame&, int, Progress*) {
    return Image();  // never called for Kernel::Scalar
  });
}

}  // namespace aolab
