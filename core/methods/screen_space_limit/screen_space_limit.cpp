#include "core/methods/screen_space_limit/screen_space_limit.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "core/base/parallel.h"
#include "core/sampling/cosine_hemisphere.h"

namespace aolab {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Frame {
  const float* depth;    // background replaced by NaN: such pixels never occlude
  const float* normals;  // prepared, 3 per pixel
  int width, height;
  CameraIntrinsics cam;
};

glm::dvec3 normal_at(const Frame& f, std::size_t idx) {
  return {f.normals[3 * idx], f.normals[3 * idx + 1], f.normals[3 * idx + 2]};
}

// The pixel q's surface is its tangent plane n_q · X = c_q (through its view-space point,
// depth at its centre, with its prepared normal), over its footprint. A point X lies behind
// it by f = n_q·X − c_q < 0 (normals face the camera). Its depth gap behind the surface,
// measured along X's own view ray, is g = r·(−f)/(−n_q·X) with r = X's depth (the plane
// meets that view ray at depth r·c_q/(n_q·X)).
struct Surface {
  glm::dvec3 n;
  double c;
  double p_len;  // |P_q|, the scale of c's rounding
};

// Whether the ray X(λ) = P + λω, over λ ∈ [l0, l1] (its stretch inside q's footprint), passes
// behind q's surface by less than T somewhere. f is linear in λ; the gap g is monotone or
// concave over the stretch (r and −f are linear and −f/(−c − f) is concave increasing in
// −f), so its smallest value on the part behind the surface is at that part's ends: l0, l1,
// or where f crosses 0 (gap 0).
// A ray's gap behind a crossed pixel's surface, the depth it would need the solid to reach:
// the ray is blocked at thickness T when its gap is below T, and in a height field when the
// gap is below kInf. kInf: never behind; 0: it crosses the surface (blocked for any T > 0);
// kBehindUnbounded: behind, but running parallel to or away from the camera plane, so only a
// height field blocks it.
constexpr double kBehindUnbounded = std::numeric_limits<double>::max();

double pixel_gap(const Surface& s, const glm::dvec3& p, const glm::dvec3& w, double l0, double l1) {
  const double a = glm::dot(s.n, p) - s.c, b = glm::dot(s.n, w);
  const double f0 = a + b * l0, f1 = a + b * l1;
  if (f0 >= 0.0 && f1 >= 0.0) return kInf;  // in front all along: the common case, cheaply
  const glm::dvec3 x0 = p + l0 * w, x1 = p + l1 * w;
  const double tol0 = kScreenSpaceLimitPlaneTolerance * (glm::length(x0) + s.p_len);
  const double tol1 = kScreenSpaceLimitPlaneTolerance * (glm::length(x1) + s.p_len);
  const bool behind0 = f0 < -tol0, behind1 = f1 < -tol1;
  if (!behind0 && !behind1) return kInf;
  if (behind0 != behind1) return 0.0;  // crossing: the gap starts at 0
  const auto gap = [&](const glm::dvec3& x, double f) {
    const double nx = glm::dot(s.n, x);
    return nx < 0.0 ? -x.z * (-f) / (-nx) : kBehindUnbounded;
  };
  return std::min(gap(x0, f0), gap(x1, f1));
}

// Whether a ray with this smallest gap is blocked at thickness T (kScreenSpaceLimitUnbounded
// and above: a height field, where being behind anything blocks).
bool blocked_at(double gap, double thickness) {
  return thickness >= kScreenSpaceLimitUnbounded ? gap < kInf : gap < thickness;
}

// Marches the ray from the receiver P (pixel (px, py), depth d) along the unit direction ω up
// to view-space length R, over every pixel its projection crosses: a 2-D
// Amanatides–Woo traversal of the projected segment, clipped to the image. Screen-space
// parameter t ∈ [0, 1] maps to λ by perspective: 1/depth is linear in t, so
// λ = L·t·r_A / ((1 − t)·r_B + t·r_A). The receiver's own pixel is skipped: its surface is P's
// tangent plane, which no ray of the hemisphere goes behind. A ray that leaves the image
// ends there, unoccluded (nothing is known beyond the border).
// The smallest gap (pixel_gap) along the ray, marched until it falls below `stop_below`: from
// there on every thickness asked for blocks the ray, and the rest of the march cannot change
// an answer.
double ray_gap(const Frame& f, const ScreenSpaceLimitSettings& s, int px, int py, double d,
               const glm::dvec3& p, const glm::dvec3& w, double stop_below) {
  double length = s.radius;
  // Towards the camera the depth falls as −ω.z per unit length; stop short of the camera plane.
  if (w.z > 0.0) length = std::min(length, d * (1.0 - kScreenSpaceLimitNearCut) / w.z);
  const glm::dvec3 end = p + length * w;
  const double r_a = d, r_b = -end.z;
  const CameraIntrinsics& cam = f.cam;
  const double ax = px + 0.5, ay = py + 0.5;
  const double bx = cam.cx + double(cam.fx) * end.x / r_b;
  const double by = cam.cy - double(cam.fy) * end.y / r_b;
  const double dx = bx - ax, dy = by - ay;
  if (!std::isfinite(dx) || !std::isfinite(dy)) return kInf;

  // Liang–Barsky: the part of the segment inside [0, W] × [0, H]; it starts inside.
  double t_end = 1.0;
  if (dx > 0.0) t_end = std::min(t_end, (f.width - ax) / dx);
  if (dx < 0.0) t_end = std::min(t_end, -ax / dx);
  if (dy > 0.0) t_end = std::min(t_end, (f.height - ay) / dy);
  if (dy < 0.0) t_end = std::min(t_end, -ay / dy);

  const int step_x = dx > 0.0 ? 1 : -1, step_y = dy > 0.0 ? 1 : -1;
  const double delta_x = dx != 0.0 ? 1.0 / std::abs(dx) : kInf;
  const double delta_y = dy != 0.0 ? 1.0 / std::abs(dy) : kInf;
  // The pixel centre is half a pixel from either edge.
  double next_x = 0.5 * delta_x, next_y = 0.5 * delta_y;
  int ix = px, iy = py;
  double t_in = 0.0;
  const auto lambda = [&](double t) { return length * t * r_a / ((1.0 - t) * r_b + t * r_a); };
  double smallest = kInf;
  // Each step enters a new pixel, and a straight segment crosses at most W + H of them.
  for (int guard = f.width + f.height + 2; guard > 0; --guard) {
    const double t_out = std::min({next_x, next_y, t_end});
    if (ix != px || iy != py) {
      const std::size_t idx = std::size_t(iy) * f.width + ix;
      const float dq = f.depth[idx];
      if (dq == dq) {  // background never occludes
        const glm::dvec3 pq = glm::dvec3(cam.view_position(float(ix) + 0.5f, float(iy) + 0.5f, dq));
        const glm::dvec3 nq = normal_at(f, idx);
        const Surface surface{nq, glm::dot(nq, pq), glm::length(pq)};
        smallest = std::min(smallest, pixel_gap(surface, p, w, lambda(t_in), lambda(t_out)));
        if (smallest < stop_below) return smallest;
      }
    }
    if (t_out >= t_end) break;
    if (next_x < next_y)
      ix += step_x, t_in = next_x, next_x += delta_x;
    else
      iy += step_y, t_in = next_y, next_y += delta_y;
    if (ix < 0 || ix >= f.width || iy < 0 || iy >= f.height) break;
  }
  return smallest;
}

// The pixel's AO at each thickness of `thicknesses`, written to out[k] (1 on background).
void screen_space_limit_pixel(const Frame& f, const ScreenSpaceLimitSettings& s,
                              const std::vector<double>& thicknesses, double stop_below, int x,
                              int y, std::vector<double>& blocked, float* out) {
  const std::size_t idx = std::size_t(y) * f.width + x;
  const float depth = f.depth[idx];
  const std::size_t n_thick = thicknesses.size();
  if (!(depth == depth)) {  // background
    std::fill(out, out + n_thick, 1.0f);
    return;
  }
  const double d = depth;
  const glm::dvec3 p(f.cam.view_position(float(x) + 0.5f, float(y) + 0.5f, depth));
  const glm::dvec3 n = normal_at(f, idx);
  std::fill(blocked.begin(), blocked.end(), 0.0);
  for_each_cosine_ray(s.rays, std::uint32_t(s.seed), x, y, n,
                      [&](const glm::dvec3& w, double weight) {
                        const double gap = ray_gap(f, s, x, y, d, p, w, stop_below);
                        if (gap == kInf) return;  // behind nothing: unblocked at every thickness
                        for (std::size_t i = 0; i < n_thick; ++i)
                          if (blocked_at(gap, thicknesses[i])) blocked[i] += weight;
                      });
  for (std::size_t i = 0; i < n_thick; ++i) out[i] = float(std::clamp(1.0 - blocked[i], 0.0, 1.0));
}

}  // namespace

std::vector<Image> screen_space_limit_thicknesses(const GBuffer& g,
                                                  const ScreenSpaceLimitSettings& settings,
                                                  const std::vector<float>& thicknesses,
                                                  const RunOptions& options) {
  g.validate();
  require_normal(g, "screen_space_limit");
  if (thicknesses.empty())
    throw std::invalid_argument("screen_space_limit: thicknesses must name at least one");
  std::vector<double> wanted;
  // Once a ray's gap is below the thinnest non-zero thickness, every thickness asked for
  // blocks it (zero blocks nothing and does not count).
  double stop_below = kInf;
  for (float t : thicknesses) {
    ScreenSpaceLimitSettings one = settings;
    one.thickness = t;
    validate_settings(one, kScreenSpaceLimitFields);
    wanted.push_back(t);
    if (t > 0.0f) stop_below = std::min(stop_below, t >= kScreenSpaceLimitUnbounded ? kInf : t);
  }
  const int w = g.width(), h = g.height();
  const int threads = resolve_threads(options.threads);

  const Buffer<float> depth = depth_with_background_as_nan(g, threads);
  const Image normals = prepared_normals(g, threads);
  const Frame frame{depth.data(), normals.data(), w, h, g.camera};
  const std::size_t n = wanted.size();

  std::vector<Image> out(n, Image(w, h, 1, 1.0f));
  // Zero thickness everywhere: no solid behind any surface, nothing occludes.
  const bool nothing_occludes =
      std::all_of(wanted.begin(), wanted.end(), [](double t) { return t == 0.0; });
  if (options.progress) options.progress->total += h;
  parallel_for_rows(
      h, threads,
      [&](int y0, int y1) {
        if (nothing_occludes) return;
        std::vector<double> blocked(n);
        std::vector<float> values(n);
        for (int y = y0; y < y1; ++y)
          for (int x = 0; x < w; ++x) {
            screen_space_limit_pixel(frame, settings, wanted, stop_below, x, y, blocked,
                                     values.data());
            for (std::size_t i = 0; i < n; ++i) out[i](x, y) = values[i];
          }
      },
      options.progress);
  return out;
}

Image screen_space_limit(const GBuffer& g, const ScreenSpaceLimitSettings& s,
                         const RunOptions& options) {
  validate_settings(s, kScreenSpaceLimitFields);
  return std::move(screen_space_limit_thicknesses(g, s, {s.thickness}, options).front());
}

Method screen_space_limit_method() {
  Method m = registered_method(
      "screen_space_limit", "Screen-space limit (bound)",
      "the reference's definition (Cycles' AO pass) evaluated on the depth buffer; a bound "
      "for the study, not a published method",
      kScreenSpaceLimitFields, screen_space_limit);
  m.needs_normal = true;
  m.bound = true;
  return m;
}

}  // namespace aolab
