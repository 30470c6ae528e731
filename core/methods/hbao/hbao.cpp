#include "core/methods/hbao/hbao.h"

#include <algorithm>
#include <glm/geometric.hpp>
#include <limits>
#include <vector>

#include "core/base/parallel.h"
#include "core/methods/hbao/hbao_shared.h"
#include "core/sampling/random.h"

namespace aolab {

HbaoPixelPattern hbao_pixel_pattern(const HbaoSettings& s, int x, int y) {
  const auto seed = std::uint32_t(s.seed);
  return {s.random_rotation ? pixel_random(seed, x, y, 0) : 0.0f,
          s.jitter ? pixel_random(seed, x, y, 1) : 0.0f};
}

namespace {

constexpr float kFloatEpsilon = 1.0f / 16777216.0f;  // 2^-24, unit roundoff of float32

// Sine of the elevation of the tangent plane (normal n) in view-space azimuth (ux, uy): the
// tangent vector (u, tz) with n·(u, tz) = 0, tz = -(n.xy·u)/n.z. A camera-facing normal can
// have n.z < 0 off-axis, hence the sign. Only a fallback (see tangent_on_ray).
inline float tangent_sin_in_azimuth(const glm::vec3& n, float ux, float uy) {
  const float along = n.x * ux + n.y * uy;
  const float denom = std::sqrt(along * along + n.z * n.z * (ux * ux + uy * uy));
  if (!(denom > 0.0f)) return 0.0f;
  return (n.z < 0.0f ? along : -along) / denom;
}

// Sine of the elevation, seen from P, of the point at depth z on the view ray through the
// image point P's pixel centre + (qx, qy): D = X - P without cancellation, since
// X.x - P.x = (qx·z + ox·(z - d)) / fx with ox = P's pixel centre - cx (likewise y), and
// D.z = d - z.
inline float elevation_sin_on_ray(float qx, float qy, float z, float d, float ox, float oy,
                                  float inv_fx, float inv_fy) {
  const float dz_ = z - d;
  const float dx = (qx * z + ox * dz_) * inv_fx;
  const float dy = -(qy * z + oy * dz_) * inv_fy;
  const float len = std::sqrt(dx * dx + dy * dy + dz_ * dz_);
  return len > 0.0f ? -dz_ / len : 0.0f;
}

// The paper's tangent construction (§3), "intersect a view ray with the tangent plane
// defined by P and n", for the ray through P's pixel centre + (qx, qy) pixels. With
// r = view ray at depth 1 and P = d·r0, the hit is at depth tau = d (n·r0)/(n·r). Returns
// sin t, and tau (infinite when the ray never meets the plane in front of the camera: then
// t is the elevation of the ray's direction, the limit of far points on it).
struct RayTangent {
  float sin_t;
  float tau;
};
inline RayTangent tangent_on_ray(const glm::vec3& n, float n_r0, float qx, float qy, float d,
                                 float ox, float oy, float inv_fx, float inv_fy) {
  const glm::vec3 r((ox + qx) * inv_fx, -(oy + qy) * inv_fy, -1.0f);
  const float n_r = glm::dot(n, r);
  const float tau = d * n_r0 / n_r;
  if (n_r < 0.0f && tau > 0.0f && std::isfinite(tau))
    return {elevation_sin_on_ray(qx, qy, tau, d, ox, oy, inv_fx, inv_fy), tau};
  return {r.z / glm::length(r), std::numeric_limits<float>::infinity()};
}

using Frame = HorizonFrame;

// The paper's one t(θ) per direction (per_sample_tangent off): from the ray one pixel along
// θ, or in azimuth where that ray never meets the tangent plane.
float direction_tangent_sin(const HorizonReceiver& p, float step_x, float step_y, float c,
                            float s) {
  const float len = std::sqrt(step_x * step_x + step_y * step_y);
  const RayTangent rt =
      tangent_on_ray(p.n, p.n_r0, step_x / len, step_y / len, p.d, p.ox, p.oy, p.inv_fx, p.inv_fy);
  return std::isfinite(rt.tau) ? rt.sin_t : tangent_sin_in_azimuth(p.n, c, s);
}

// A sample that may become the horizon: its gain sin α − sin t and its distance r = |D|.
struct Candidate {
  float gain, r;
};

// t at the sample itself: the tangent plane on the sample's own view ray rs, met at depth tau
// (tangent_on_ray). S counts only if it lies nearer than the plane by more than float32 depth
// and normal rounding. The cheap sign test comes first: most samples of open surfaces fail it.
bool per_sample_candidate(const HorizonReceiver& p, float qx, float qy, float ds, float dd,
                          float r2, Candidate& out) {
  const glm::vec3 rs((p.ox + qx) * p.inv_fx, -(p.oy + qy) * p.inv_fy, -1.0f);
  const float n_rs = glm::dot(p.n, rs);
  const float tau = p.d * p.n_r0 / n_rs;
  const bool hits = n_rs < 0.0f && tau > 0.0f && std::isfinite(tau);
  if (hits && !(tau > ds)) return false;
  const float rs_len = glm::length(rs);
  const float grazing_s = rs_len / std::abs(n_rs);
  const float tolerance = kFloatEpsilon * std::max(ds, hits ? tau : ds) *
                          (kTangentDepthUlps + kTangentNormalUlps * (p.grazing_p + grazing_s));
  if (!((hits ? tau : std::numeric_limits<float>::infinity()) - ds > tolerance)) return false;
  const float sin_t =
      hits ? elevation_sin_on_ray(qx, qy, tau, p.d, p.ox, p.oy, p.inv_fx, p.inv_fy) : rs.z / rs_len;
  out.r = std::sqrt(r2);
  out.gain = -dd / out.r - sin_t;
  return true;
}

// integral = cosine: the direction's term for a counted sample at D = (dx, dy, −dd), |D| = r,
// is the cosine band from t to the sample's elevation (hbao_cosine_band). Per-sample tangents:
// in the sample's own azimuth û = D.xy/|D.xy|, with t the tangent plane's elevation there.
// One tangent per direction: in the direction's azimuth (c, sn), with its t(θ).
float cosine_gain(const HorizonReceiver& p, bool per_sample, float sin_t_dir, float c, float sn,
                  float dx, float dy, float dd, float r) {
  const float sin_a = -dd / r, hor = std::sqrt(dx * dx + dy * dy), cos_a = hor / r;
  if (!per_sample) {
    const float a = p.n.x * c + p.n.y * sn;
    const float cos_t = std::sqrt(std::max(0.0f, 1.0f - sin_t_dir * sin_t_dir));
    return hbao_cosine_band(a, p.n.z, sin_a, cos_a, sin_t_dir, cos_t);
  }
  const float ux = hor > 0.0f ? dx / hor : c, uy = hor > 0.0f ? dy / hor : sn;
  const float a = p.n.x * ux + p.n.y * uy;
  const float rho = std::sqrt(a * a + p.n.z * p.n.z);
  if (!(rho > 0.0f)) return 0.0f;  // n ⟂ the whole slice: n·ω = 0 in it
  // tan t = −a/n_z (tangent_sin_in_azimuth), t in [−π/2, π/2].
  const float sin_t = (p.n.z < 0.0f ? a : -a) / rho, cos_t = std::abs(p.n.z) / rho;
  return hbao_cosine_band(a, p.n.z, sin_a, cos_a, sin_t, cos_t);
}

// The sample on texel (sx, sy) at depth ds as a horizon candidate; false if it lies beyond R
// (ignored, §3), is background (NaN) or is not above the tangent by more than rounding. The
// tangent test decides whether it counts; `integral` decides its gain.
bool sample_candidate(const HorizonReceiver& p, const HbaoSettings& s, float radius2,
                      float sin_t_dir, float c, float sn, int sx, int sy, float ds,
                      Candidate& out) {
  const float qx = float(sx - p.x), qy = float(sy - p.y);
  // D = S − P without cancellation (see elevation_sin_on_ray).
  const float dd = ds - p.d;
  const float dx = (qx * ds + p.ox * dd) * p.inv_fx;
  const float dy = -(qy * ds + p.oy * dd) * p.inv_fy;
  const float r2 = dx * dx + dy * dy + dd * dd;
  if (!(r2 <= radius2) || r2 == 0.0f) return false;
  bool counts;
  if (s.per_sample_tangent) {
    counts = per_sample_candidate(p, qx, qy, ds, dd, r2, out);
  } else {
    out.r = std::sqrt(r2);
    out.gain = -dd / out.r - sin_t_dir;
    const float tolerance =
        kHbaoNormalTolerance + kTangentDepthUlps * kFloatEpsilon * std::max(p.d, ds) / out.r;
    counts = out.gain > tolerance;
  }
  if (counts && s.integral == int(HbaoIntegral::Cosine))
    out.gain = cosine_gain(p, s.per_sample_tangent, sin_t_dir, c, sn, dx, dy, dd, out.r);
  return counts;
}

// The occlusion of direction (c, s): eq. 3's (sin h − sin t)·W(r) of the horizon, or with
// incremental_attenuation eq. 2's rises of sin h, each weighted by W of the sample that caused
// it; with integral = cosine the cosine band replaces sin h − sin t, with attenuation = none
// W = 1.
float march_direction(const Frame& f, const HbaoSettings& s, const HorizonReceiver& p, float jitter,
                      float c, float sn) {
  const float radius = s.radius, radius2 = radius * radius, inv_radius = 1.0f / radius;
  float step_x, step_y;
  horizon_step(f.cam, radius, s.steps, p.d, c, sn, step_x, step_y);
  const float sin_t_dir =
      s.per_sample_tangent ? 0.0f : direction_tangent_sin(p, step_x, step_y, c, sn);
  // Its length in pixels, for the MIP level of far samples (a sum of products, no fused
  // multiply-add, so that the SIMD kernel computes the same bits).
  const float step_len = std::sqrt(step_x * step_x + step_y * step_y);
  float best_gain = 0.0f, best_r = 0.0f;
  float rises = 0.0f;  // eq. 2 mode: Σ (rise of sin h) · W(r of the sample that raised it)
  for (int i = 1; i <= s.steps; ++i) {
    const float t = float(i) - jitter;
    const float sx_f = p.px + t * step_x, sy_f = p.py + t * step_y;
    // Leaving the image along a straight line is final; the test also rejects inf/NaN.
    if (!(sx_f >= 0.0f && sx_f < float(f.width) && sy_f >= 0.0f && sy_f < float(f.height))) break;
    int sx = int(sx_f), sy = int(sy_f);  // snap to the texel (its centre below)
    const std::size_t index = horizon_sample_index(f, t * step_len, sx, sy);
    if (sx == p.x && sy == p.y) continue;
    Candidate cand;
    if (!sample_candidate(p, s, radius2, sin_t_dir, c, sn, sx, sy, f.depth[index], cand)) continue;
    if (cand.gain > 0.0f && (best_r == 0.0f || cand.gain > best_gain + kHbaoHorizonTie)) {
      rises += (cand.gain - best_gain) * std::max(0.0f, 1.0f - cand.r * inv_radius);
      best_gain = cand.gain, best_r = cand.r;
    }
  }
  if (s.attenuation == int(HbaoAttenuation::None)) return best_gain;  // W = 1 within R
  return s.incremental_attenuation
             ? rises
             : best_gain * std::max(0.0f, 1.0f - best_r * inv_radius);  // eq. 3
}

float hbao_pixel(const Frame& f, const HbaoSettings& s, const HorizonDirections& directions, int x,
                 int y, float* dir_cos, float* dir_sin) {
  const std::size_t idx = std::size_t(y) * f.width + x;
  const float d = f.depth[idx];
  if (!(d == d)) return 1.0f;  // background
  const HorizonReceiver p = horizon_receiver(
      f.cam, x, y, d, {f.normals[3 * idx], f.normals[3 * idx + 1], f.normals[3 * idx + 2]});
  const HbaoPixelPattern pattern = hbao_pixel_pattern(s, x, y);
  directions.rotated(pattern.rotation, dir_cos, dir_sin);
  float occlusion = 0.0f;
  for (int k = 0; k < s.directions; ++k)
    occlusion += march_direction(f, s, p, pattern.jitter, dir_cos[k], dir_sin[k]);
  const float ao = 1.0f - occlusion / float(s.directions);
  return std::clamp(ao, 0.0f, 1.0f);
}

}  // namespace

Image hbao(const GBuffer& g, const HbaoSettings& s, const RunOptions& options) {
  g.validate();
  require_normal(g, "hbao");
  validate_settings(s, kHbaoFields);
  const int w = g.width(), h = g.height();
  const int threads = resolve_threads(options.threads);

  // Working copies: depth with background as NaN, normals cleaned up (gbuffer.h); with
  // far samples on the MIP chain, its levels after the depth.
  Buffer<float> depth = depth_with_background_as_nan(g, threads);
  const Image normals = prepared_normals(g, threads);
  const Frame frame = horizon_frame(depth, normals, g.camera, s.mip_distance, threads);
  if (options.kernel == Kernel::Simd) return hbao_simd(frame, s, threads, options.progress);

  const HorizonDirections directions(s.directions);
  return image_from_pixels(
      w, h, threads, options.progress,
      [&] { return std::vector<float>(2 * std::size_t(s.directions)); },
      [&](std::vector<float>& dirs, int x, int y) {
        return hbao_pixel(frame, s, directions, x, y, dirs.data(), dirs.data() + s.directions);
      });
}

Method hbao_method() {
  Method m =
      registered_method("hbao", "Horizon-based ambient occlusion",
                        "Bavoil, Sainz, Dimitrov 2008, Image-Space Horizon-Based Ambient Occlusion",
                        kHbaoFields, hbao);
  m.needs_normal = true;
  m.has_simd_kernel = true;
  return m;
}

}  // namespace aolab
