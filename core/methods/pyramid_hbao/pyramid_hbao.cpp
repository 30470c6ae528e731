#include "core/methods/pyramid_hbao/pyramid_hbao.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>
#include <vector>

#include "core/base/parallel.h"
#include "core/filters/blur.h"
#include "core/horizon/receiver.h"
#include "core/methods/pyramid_hbao/pyramid_hbao_shared.h"
#include "core/sampling/blue_noise.h"
#include "core/sampling/random.h"

namespace aolab {

namespace {

constexpr float kFloatEpsilon = 1.0f / 16777216.0f;  // 2^-24, unit roundoff of float32
constexpr float kInfinity = std::numeric_limits<float>::infinity();

// Streams of pixel_random: two per direction (its place in the sector, its start step).
constexpr std::uint32_t kSectorStream = 0;
constexpr std::uint32_t kStartStream = 1;

}  // namespace

void pyramid_hbao_directions(const PyramidHbaoSettings& s, int x, int y,
                             PyramidHbaoDirection* out) {
  const auto seed = std::uint32_t(s.seed);
  // §3.5: "uniformly selected azimuth directions are rotated by a random angle generated
  // based on a value from blue noise texture (with resolution 32x32 pixels)". The seed
  // shifts the tiled texture and adds a global rotation: the blue-noise arrangement of the
  // angles between neighbouring pixels is unchanged.
  float rotation = 0.0f;
  if (s.rotation) {
    const std::uint32_t h = pcg_hash(seed ^ 0x6A09E667u);
    const float global = float(pcg_hash(h) >> 8) * kFloatEpsilon;
    rotation =
        blue_noise_value(blue_noise_ranks(), x + int(h & 31u), y + int((h >> 5) & 31u)) + global;
    if (rotation >= 1.0f) rotation -= 1.0f;
  }
  const float sector = float(2.0 * std::numbers::pi / s.directions);
  for (int k = 0; k < s.directions; ++k) {
    // §3.5: "the uniform distribution of azimuth directions was changed to a random one" —
    // read as stratified: one direction at a random place in each sector, so the D
    // directions still cover the circle evenly.
    const float place = s.random_directions
                            ? pixel_random(seed, x, y, 2u * std::uint32_t(k) + kSectorStream)
                            : 0.0f;
    const float theta = sector * (float(k) + rotation + place);
    out[k].cos_theta = std::cos(theta);
    out[k].sin_theta = std::sin(theta);
    // §3.5: "starting step size was multiplied by a random value selected for each
    // azimuth direction".
    out[k].start = s.random_start
                       ? kPyramidHbaoStartMin +
                             (kPyramidHbaoStartMax - kPyramidHbaoStartMin) *
                                 pixel_random(seed, x, y, 2u * std::uint32_t(k) + kStartStream)
                       : 1.0f;
  }
}

namespace {

struct Frame {
  const DepthPyramid* pyramid;  // level 0 = depth with background as NaN
  int levels;                   // levels to march (capped at the pyramid's)
  const float* normals;         // prepared, 3 per pixel
  int width, height;
  CameraIntrinsics cam;
};

// Eq. 8's term W(r)·sin α of the texel read on level l, into `weighted`; false if the texel
// is background, at or beyond R (W = 0, eq. 7; with attenuation none, beyond R) or not above
// P's tangent plane.
bool texel_contribution(const Frame& f, const HorizonReceiver& p, const PyramidTexel& texel, int l,
                        float radius2, float inv_radius, bool attenuate, float& weighted) {
  const float ds = texel.depth;
  // §3.4 step 2a: "restore the position in the three-dimensional space" — at the texel's
  // centroid (its centre where its footprint is whole), at the averaged depth. D = S − P
  // without cancellation: S.x − P.x = (qx·ds + ox·(ds − d))/fx with qx = centroid − P's
  // centre (likewise y), and D.z = d − ds.
  const float qx = texel.x - p.px, qy = texel.y - p.py;
  const float dd = ds - p.d;
  const float dx = (qx * ds + p.ox * dd) * p.inv_fx;
  const float dy = -(qy * ds + p.oy * dd) * p.inv_fy;
  const float r2 = dx * dx + dy * dy + dd * dd;
  // W(r) = max(0, 1 − r/R) (eq. 7) is 0 from r = R on; without attenuation (W = 1, the
  // reference's hard cut-off) a texel at exactly R still counts. Background is NaN.
  if (!(attenuate ? r2 < radius2 : r2 <= radius2) || r2 == 0.0f) return false;
  // Above the tangent plane? The plane of (P, n) meets the sample's view ray rs at depth
  // tau = d (n·r0)/(n·rs); the sample counts only if it lies nearer than that by more than
  // float32 rounding (kPyramidHbaoDepthUlps ...), so a plane never occludes itself. A ray
  // that never meets the plane in front of the camera passes above it.
  const glm::vec3 rs((texel.x - f.cam.cx) * p.inv_fx, -(texel.y - f.cam.cy) * p.inv_fy, -1.0f);
  const float n_rs = glm::dot(p.n, rs);
  const float tau = p.d * p.n_r0 / n_rs;
  const bool hits = n_rs < 0.0f && tau > 0.0f && std::isfinite(tau);
  if (hits && !(tau > ds)) return false;  // the cheap test first: most samples fail it
  const float grazing_s = glm::length(rs) / std::abs(n_rs);
  const float tolerance = kFloatEpsilon * std::max(ds, hits ? tau : ds) *
                          (kPyramidHbaoDepthUlps + kPyramidHbaoLevelUlps * float(l) +
                           kPyramidHbaoNormalUlps * (p.grazing_p + grazing_s));
  if (!((hits ? tau : kInfinity) - ds > tolerance)) return false;
  // sin α = n·D/|D|: the elevation above the tangent plane, in the hemisphere about n of
  // §2.2.1 (ω = (cos θ cos α, sin α, sin θ cos α), n the middle axis; eq. 2 integrates α
  // from 0, the tangent plane).
  const float r = std::sqrt(r2);
  const float sin_alpha = std::clamp((p.n.x * dx + p.n.y * dy - p.n.z * dd) / r, 0.0f, 1.0f);
  weighted = attenuate ? (1.0f - r * inv_radius) * sin_alpha : sin_alpha;
  return true;
}

// Eq. 8 for one direction: the largest weighted contribution max_i W(r_i)·sin α_i over the
// samples of the march (§3.4 step 2), 0 if no sample occludes.
float march_direction(const Frame& f, const PyramidHbaoSettings& s, const HorizonReceiver& p,
                      const PyramidHbaoDirection& dir) {
  const float radius2 = s.radius * s.radius, inv_radius = 1.0f / s.radius;
  const bool attenuate = s.attenuation == int(PyramidHbaoAttenuation::Linear);
  // The view-space azimuth θ as an image direction (image y points down, view y up) and
  // the projected radius along it, at P's depth: R spans R·|e|/d pixels.
  const float ex = dir.cos_theta * f.cam.fx, ey = -dir.sin_theta * f.cam.fy;
  const float e_len = std::sqrt(ex * ex + ey * ey);
  const float ux = ex / e_len, uy = ey / e_len;
  const float reach = s.radius * e_len / p.d;  // pixels; +inf for a huge R
  float best = 0.0f;
  float t = 0.0f;  // distance marched from P's centre, full-resolution pixels
  for (int l = 0; l < f.levels; ++l) {
    // §3.4 step 2: S reads on level l with step m·K^l (the step is multiplied by K per
    // level, step 2b), continuing from where the previous level ended.
    const DepthPyramidLevel& level = f.pyramid->level(l);
    const int scale = level.scale;
    const float step = dir.start * float(scale);
    const int own_x = p.x / scale, own_y = p.y / scale;  // P's texel on this level
    for (int i = 0; i < s.samples; ++i) {
      t += step;
      // Past the projected radius every sample at P's depth has W = 0 (eq. 7), and leaving
      // the image along a straight line is final: either ends the direction. The
      // comparisons also stop on inf/NaN.
      if (!(t <= reach)) return best;
      const float sx_f = p.px + t * ux, sy_f = p.py + t * uy;
      if (!(sx_f >= 0.0f && sx_f < float(f.width) && sy_f >= 0.0f && sy_f < float(f.height)))
        return best;
      const int tx = int(sx_f) / scale, ty = int(sy_f) / scale;
      if (tx == own_x && ty == own_y) continue;  // P's own texel on this level
      // Eq. 8: keep the occluder with the largest weighted contribution, instead of HBAO's
      // highest horizon.
      float weighted;
      if (texel_contribution(f, p, level(tx, ty), l, radius2, inv_radius, attenuate, weighted))
        best = std::max(best, weighted);
    }
  }
  return best;
}

float pyramid_hbao_pixel(const Frame& f, const PyramidHbaoSettings& s, int x, int y,
                         PyramidHbaoDirection* dirs) {
  const std::size_t idx = std::size_t(y) * f.width + x;
  const float d = f.pyramid->level(0).texels[idx].depth;
  if (!(d == d)) return 1.0f;  // background
  // §3.4 step 1: P from the depth buffer, n from the normal map.
  const HorizonReceiver p = horizon_receiver(
      f.cam, x, y, d, {f.normals[3 * idx], f.normals[3 * idx + 1], f.normals[3 * idx + 2]});

  pyramid_hbao_directions(s, x, y, dirs);
  float occlusion = 0.0f;
  for (int k = 0; k < s.directions; ++k) occlusion += march_direction(f, s, p, dirs[k]);
  // §3.4 step 3: average the directions. Every term lies in [0, 1], so A does too; the
  // clamp only guards the rounding of the division.
  return std::clamp(1.0f - occlusion / float(s.directions), 0.0f, 1.0f);
}

}  // namespace

Image pyramid_hbao(const GBuffer& g, const PyramidHbaoSettings& s, const RunOptions& options) {
  g.validate();
  require_normal(g, "pyramid_hbao");
  validate_settings(s, kPyramidHbaoFields);
  const int w = g.width(), h = g.height();
  const int threads = resolve_threads(options.threads);
  if (options.progress && options.progress->cancel.load()) throw Cancelled();

  // §3.2 stage 1: the depth pyramid (level 0 = depth with background as NaN); then the
  // normals made well defined (gbuffer.h).
  if (options.kernel == Kernel::Simd && w < kPyramidHbaoSimdMaxSide &&
      h < kPyramidHbaoSimdMaxSide) {
    // The same pyramid laid out for gathers, and the SIMD kernel.
    const GatherPyramid pyramid(g, s.reduction, s.levels, threads);
    const Image normals = prepared_normals(g, threads);
    Image out = pyramid_hbao_simd(pyramid, normals.data(), g.camera, s, threads, options.progress);
    if (s.gaussian_filter) return gaussian_blur(out.view(), g, BlurSettings{}, threads);
    return out;
  }
  const DepthPyramid pyramid(g, s.reduction, s.levels, threads);
  const Image normals = prepared_normals(g, threads);
  const Frame frame{&pyramid, pyramid.levels(), normals.data(), w, h, g.camera};

  // §3.2 stage 2: the occlusion of every pixel, rows in parallel.
  Image out = image_from_pixels(
      w, h, threads, options.progress,
      [&] { return std::vector<PyramidHbaoDirection>(std::size_t(s.directions)); },
      [&](std::vector<PyramidHbaoDirection>& dirs, int x, int y) {
        return pyramid_hbao_pixel(frame, s, x, y, dirs.data());
      });
  // §3.5: "a separable Gaussian filter with the value σ = 1.5 and usage of 5 samples".
  if (s.gaussian_filter) return gaussian_blur(out.view(), g, BlurSettings{}, threads);
  return out;
}

Method pyramid_hbao_method() {
  Method m = registered_method("pyramid_hbao", "Pyramid horizon-based ambient occlusion",
                               "Astapov, Frolov, Galaktionov 2021, Pyramid HBAO - a Scalable "
                               "Horizon-based Ambient Occlusion Method",
                               kPyramidHbaoFields, pyramid_hbao);
  m.needs_normal = true;
  m.has_simd_kernel = true;
  return m;
}

}  // namespace aolab
