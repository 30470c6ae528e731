#include "core/methods/hbao/hbao.h"

#include <algorithm>
#include <glm/geometric.hpp>
#include <limits>
#include <vector>

#include "core/base/parallel.h"
#include "core/sampling/random.h"

namespace aolab {

HbaoPixelPattern hbao_pixel_pattern(const HbaoSettings& s, int x, int y) {
  const auto seed = std::uint32_t(s.seed);
  return {s.random_rotation ? pixel_random(seed, x, y, 0) : 0.0f,
          s.jitter ? pixel_random(seed, x, y, 1) : 0.0f};
}

HbaoDirections::HbaoDirections(int directions) : base_cos_(directions), base_sin_(directions) {
  const double spacing = 2.0 * std::numbers::pi / directions;
  for (int k = 0; k < directions; ++k) {
    base_cos_[k] = float(std::cos(spacing * k));
    base_sin_[k] = float(std::sin(spacing * k));
  }
}

void HbaoDirections::rotated(float rotation, float* cos_out, float* sin_out) const {
  const float phi = float(2.0 * std::numbers::pi / size() * rotation);
  const float cp = std::cos(phi), sp = std::sin(phi);
  for (int k = 0; k < size(); ++k) {
    cos_out[k] = base_cos_[k] * cp - base_sin_[k] * sp;
    sin_out[k] = base_sin_[k] * cp + base_cos_[k] * sp;
  }
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

struct Frame {
  const float* depth;    // background replaced by NaN, so every test on it fails
  const float* normals;  // prepared, 3 per pixel
  int width, height;
  CameraIntrinsics cam;
};

float hbao_pixel(const Frame& f, const HbaoSettings& s, const HbaoDirections& directions, int x,
                 int y, float* dir_cos, float* dir_sin) {
  const std::size_t idx = std::size_t(y) * f.width + x;
  const float d = f.depth[idx];
  if (!(d == d)) return 1.0f;  // background
  const glm::vec3 n(f.normals[3 * idx], f.normals[3 * idx + 1], f.normals[3 * idx + 2]);
  const float px = float(x) + 0.5f, py = float(y) + 0.5f;
  const float ox = px - f.cam.cx, oy = py - f.cam.cy;  // offsets of P's pixel from (cx, cy)
  const float inv_fx = 1.0f / f.cam.fx, inv_fy = 1.0f / f.cam.fy;
  const float radius = s.radius, radius2 = radius * radius, inv_radius = 1.0f / radius;

  const HbaoPixelPattern pattern = hbao_pixel_pattern(s, x, y);
  directions.rotated(pattern.rotation, dir_cos, dir_sin);

  // |r0| / |n·r0|: how much normal rounding moves tangent-plane depths at this pixel.
  const glm::vec3 r0(ox * inv_fx, -oy * inv_fy, -1.0f);
  const float n_r0 = glm::dot(n, r0);
  const float grazing_p = glm::length(r0) / std::abs(n_r0);

  float occlusion = 0.0f;
  for (int k = 0; k < s.directions; ++k) {
    float step_x, step_y;
    hbao_step(f.cam, radius, s.steps, d, dir_cos[k], dir_sin[k], step_x, step_y);
    float sin_t_dir = 0.0f;
    if (!s.per_sample_tangent) {  // one t(θ): the ray one pixel along θ
      const float len = std::sqrt(step_x * step_x + step_y * step_y);
      const RayTangent rt =
          tangent_on_ray(n, n_r0, step_x / len, step_y / len, d, ox, oy, inv_fx, inv_fy);
      sin_t_dir =
          std::isfinite(rt.tau) ? rt.sin_t : tangent_sin_in_azimuth(n, dir_cos[k], dir_sin[k]);
    }
    float best_gain = 0.0f, best_r = 0.0f;
    float rises = 0.0f;  // eq. 2 mode: Σ (rise of sin h) · W(r of the sample that raised it)
    for (int i = 1; i <= s.steps; ++i) {
      const float t = float(i) - pattern.jitter;
      const float sx_f = px + t * step_x, sy_f = py + t * step_y;
      // Leaving the image along a straight line is final; the test also rejects inf/NaN.
      if (!(sx_f >= 0.0f && sx_f < float(f.width) && sy_f >= 0.0f && sy_f < float(f.height))) break;
      const int sx = int(sx_f), sy = int(sy_f);  // snap to the texel (its centre below)
      if (sx == x && sy == y) continue;
      const float ds = f.depth[std::size_t(sy) * f.width + sx];
      const float qx = float(sx - x), qy = float(sy - y);
      // D = S - P without cancellation (see elevation_sin_on_ray).
      const float dd = ds - d;
      const float dx = (qx * ds + ox * dd) * inv_fx;
      const float dy = -(qy * ds + oy * dd) * inv_fy;
      const float r2 = dx * dx + dy * dy + dd * dd;
      if (!(r2 <= radius2) || r2 == 0.0f) continue;  // beyond R (ignored, §3), background (NaN)
      float r;                                       // |D|, computed only for candidates
      float gain;
      if (s.per_sample_tangent) {
        // t at this sample: the tangent plane on the sample's own view ray rs, met at depth
        // tau (tangent_on_ray). S counts only if it lies nearer than the plane by more than
        // float32 depth and normal rounding. The cheap sign test comes first: most samples
        // of open surfaces fail it.
        const glm::vec3 rs((ox + qx) * inv_fx, -(oy + qy) * inv_fy, -1.0f);
        const float n_rs = glm::dot(n, rs);
        const float tau = d * n_r0 / n_rs;
        const bool hits = n_rs < 0.0f && tau > 0.0f && std::isfinite(tau);
        if (hits && !(tau > ds)) continue;
        const float rs_len = glm::length(rs);
        const float grazing_s = rs_len / std::abs(n_rs);
        const float tolerance = kFloatEpsilon * std::max(ds, hits ? tau : ds) *
                                (kHbaoDepthUlps + kHbaoNormalUlps * (grazing_p + grazing_s));
        if (!((hits ? tau : std::numeric_limits<float>::infinity()) - ds > tolerance)) continue;
        const float sin_t =
            hits ? elevation_sin_on_ray(qx, qy, tau, d, ox, oy, inv_fx, inv_fy) : rs.z / rs_len;
        r = std::sqrt(r2);
        gain = -dd / r - sin_t;
      } else {
        r = std::sqrt(r2);
        gain = -dd / r - sin_t_dir;
        const float tolerance =
            kHbaoNormalTolerance + kHbaoDepthUlps * kFloatEpsilon * std::max(d, ds) / r;
        if (!(gain > tolerance)) continue;
      }
      if (gain > 0.0f && (best_r == 0.0f || gain > best_gain + kHbaoHorizonTie)) {
        rises += (gain - best_gain) * std::max(0.0f, 1.0f - r * inv_radius);
        best_gain = gain, best_r = r;
      }
    }
    occlusion += s.incremental_attenuation
                     ? rises
                     : best_gain * std::max(0.0f, 1.0f - best_r * inv_radius);  // eq. 3
  }
  const float ao = 1.0f - occlusion / float(s.directions);
  return std::clamp(ao, 0.0f, 1.0f);
}

}  // namespace

Image hbao(const GBuffer& g, const HbaoSettings& s, const RunOptions& options) {
  g.validate();
  if (!g.has_normal())
    throw_invalid("normal",
                  "is required by hbao, which reads view-space normals (estimate them "
                  "from depth with GBuffer.prepared_normals())",
                  "none");
  validate_settings(s, kHbaoFields);
  const int w = g.width(), h = g.height();
  const int threads = resolve_threads(options.threads);

  // Working copies: depth with background as NaN, normals cleaned up (gbuffer.h).
  std::vector<float> depth(std::size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      depth[std::size_t(y) * w + x] =
          g.valid(x, y) ? g.depth(x, y) : std::numeric_limits<float>::quiet_NaN();
  const Image normals = prepared_normals(g, threads);
  const Frame frame{depth.data(), normals.data(), w, h, g.camera};

  const HbaoDirections directions(s.directions);
  Image out(w, h, 1, 1.0f);
  if (options.progress) options.progress->total += h;
  parallel_for_rows(
      h, threads,
      [&](int y0, int y1) {
        std::vector<float> dir_cos(s.directions), dir_sin(s.directions);
        for (int y = y0; y < y1; ++y)
          for (int x = 0; x < w; ++x)
            out(x, y) = hbao_pixel(frame, s, directions, x, y, dir_cos.data(), dir_sin.data());
      },
      options.progress);
  return out;
}

Method hbao_method() {
  Method m;
  m.name = "hbao";
  m.title = "Horizon-based ambient occlusion";
  m.paper = "Bavoil, Sainz, Dimitrov 2008, Image-Space Horizon-Based Ambient Occlusion";
  m.needs_normal = true;
  m.settings = describe_settings(kHbaoFields);
  m.run = [](const GBuffer& g, const SettingValues& values, const RunOptions& options) {
    return hbao(g, settings_from_values(values, kHbaoFields, "hbao"), options);
  };
  return m;
}

}  // namespace aolab
