#include "tests/textbook/hbao_textbook.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <vector>

namespace aolab {

namespace {

using dvec3 = glm::dvec3;

dvec3 position(const CameraIntrinsics& c, double px, double py, double d) {
  return {(px - c.cx) / c.fx * d, -(py - c.cy) / c.fy * d, -d};
}

double elevation(const dvec3& v) { return std::atan2(v.z, std::hypot(v.x, v.y)); }

// Elevation of the tangent plane in azimuth u: the tangent (u, tz), tz = -(n.xy·u)/n.z.
double tangent_elevation_in_azimuth(const dvec3& n, double ux, double uy) {
  const double along = n.x * ux + n.y * uy;
  const double len = std::hypot(ux, uy);
  if (n.z == 0.0) return along == 0.0 ? 0.0 : (along > 0 ? -1 : 1) * M_PI / 2;
  return std::atan(-along / (n.z * len));
}

// integral = cosine: twice the cosine-weighted solid angle between elevations t and α in the
// azimuth û, 2 ∫_t^α (n·ω) cos φ dφ with ω = (cos φ û, sin φ), from the antiderivatives
// 2∫cos²φ = φ + sin φ cos φ and 2∫sin φ cos φ = sin²φ.
double cosine_band(const dvec3& n, double ux, double uy, double alpha, double t) {
  const double a = n.x * ux + n.y * uy;
  const auto F = [&](double phi) {
    return a * (phi + std::sin(phi) * std::cos(phi)) + n.z * std::sin(phi) * std::sin(phi);
  };
  return F(alpha) - F(t);
}

}  // namespace

Image hbao_textbook(const GBuffer& g, const HbaoSettings& s) {
  const int w = g.width(), h = g.height();
  const Image normals = prepared_normals(g, 1);
  const CameraIntrinsics& cam = g.camera;
  const double R = s.radius;
  Image out(w, h, 1, 1.0f);
  const HorizonDirections directions(s.directions);
  std::vector<float> dir_cos(s.directions), dir_sin(s.directions);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (!g.valid(x, y)) continue;
      const float d = g.depth(x, y);
      const double px = x + 0.5, py = y + 0.5;
      const dvec3 P = position(cam, px, py, d);
      const dvec3 n(normals(x, y, 0), normals(x, y, 1), normals(x, y, 2));
      const dvec3 r0 = position(cam, px, py, 1.0);
      const HbaoPixelPattern pattern = hbao_pixel_pattern(s, x, y);
      directions.rotated(pattern.rotation, dir_cos.data(), dir_sin.data());
      double sum = 0.0;
      for (int k = 0; k < s.directions; ++k) {
        float step_x, step_y;
        horizon_step(cam, s.radius, s.steps, d, dir_cos[k], dir_sin[k], step_x, step_y);
        // Paper, §3: t(θ) from intersecting the view ray one pixel along θ with the tangent
        // plane of (P, n).
        double t_dir = 0.0;
        if (!s.per_sample_tangent) {
          const double len = std::hypot(double(step_x), double(step_y));
          const dvec3 ray = position(cam, px + step_x / len, py + step_y / len, 1.0);
          const double tau = glm::dot(n, P) / glm::dot(n, ray);
          if (glm::dot(n, ray) < 0 && std::isfinite(tau) && tau > 0)
            t_dir = elevation(ray * tau - P);
          else
            t_dir = tangent_elevation_in_azimuth(n, dir_cos[k], dir_sin[k]);
        }
        double best_gain = 0.0, best_r = 0.0, rises = 0.0;
        for (int i = 1; i <= s.steps; ++i) {
          const float t = float(i) - pattern.jitter;
          const float sx_f = float(px) + t * step_x, sy_f = float(py) + t * step_y;
          if (!(sx_f >= 0.0f && sx_f < float(w) && sy_f >= 0.0f && sy_f < float(h))) break;
          const int sx = int(std::floor(sx_f)), sy = int(std::floor(sy_f));
          if (sx == x && sy == y) continue;
          if (!g.valid(sx, sy)) continue;  // background never occludes
          const float ds = g.depth(sx, sy);
          const dvec3 D = position(cam, sx + 0.5, sy + 0.5, ds) - P;
          const double r = glm::length(D);
          if (r > R || r == 0.0) continue;  // samples beyond R are ignored (§3)
          const double alpha = elevation(D);
          double gain;
          if (s.per_sample_tangent) {
            // The tangent plane on this sample's own view ray; S must be nearer than it.
            const dvec3 ray = position(cam, sx + 0.5, sy + 0.5, 1.0);
            const double tau = glm::dot(n, P) / glm::dot(n, ray);
            const bool hits = glm::dot(n, ray) < 0 && tau > 0 && std::isfinite(tau);
            const double t_sample = hits ? elevation(ray * tau - P) : elevation(ray);
            const double grazing = glm::length(r0) / std::abs(glm::dot(n, r0)) +
                                   glm::length(ray) / std::abs(glm::dot(n, ray));
            const double tolerance = std::ldexp(1.0, -24) * std::max(double(ds), hits ? tau : ds) *
                                     (kTangentDepthUlps + kTangentNormalUlps * grazing);
            if (!((hits ? tau : INFINITY) - ds > tolerance)) continue;
            gain = std::sin(alpha) - std::sin(t_sample);
          } else {
            gain = std::sin(alpha) - std::sin(t_dir);
            const double tolerance = kHbaoNormalTolerance +
                                     kTangentDepthUlps * std::ldexp(1.0, -24) * std::max(d, ds) / r;
            if (!(gain > tolerance)) continue;
          }
          if (s.integral == int(HbaoIntegral::Cosine)) {
            // The band up to α in the sample's own azimuth, from the tangent there (per-sample
            // tangents), or in the direction's azimuth from t(θ).
            const double hor = std::hypot(D.x, D.y);
            if (s.per_sample_tangent) {
              const double ux = hor > 0 ? D.x / hor : dir_cos[k],
                           uy = hor > 0 ? D.y / hor : dir_sin[k];
              gain = cosine_band(n, ux, uy, alpha, tangent_elevation_in_azimuth(n, ux, uy));
            } else {
              gain = cosine_band(n, dir_cos[k], dir_sin[k], alpha, t_dir);
            }
          }
          if (gain > 0.0 && (best_r == 0.0 || gain > best_gain + kHbaoHorizonTie)) {
            rises += (gain - best_gain) * std::max(0.0, 1.0 - r / R);  // eq. 2, per rise
            best_gain = gain, best_r = r;
          }
        }
        if (s.attenuation == int(HbaoAttenuation::None))
          sum += best_gain;  // W = 1 within R
        else
          sum += s.incremental_attenuation ? rises
                                           : best_gain * std::max(0.0, 1.0 - best_r / R);  // eq. 3
      }
      out(x, y) = float(std::clamp(1.0 - sum / s.directions, 0.0, 1.0));
    }
  return out;
}

}  // namespace aolab
