#include "core/volumetric/pipes.h"

#include <glm/geometric.hpp>
#include <numbers>

#include "core/base/parallel.h"
#include "core/sampling/random.h"

namespace aolab {

namespace {
constexpr float kFloatEpsilon = 1.0f / 16777216.0f;  // 2^-24, unit roundoff of float32
}  // namespace

VaoKernel vao_kernel(const std::vector<DiskPoint>& points) {
  VaoKernel k;
  for (const auto& p : points) {
    k.x.push_back(p.x);
    k.y.push_back(p.y);
    k.h.push_back(float(std::sqrt(std::max(0.0, 1.0 - double(p.x) * p.x - double(p.y) * p.y))));
  }
  return k;
}

VaoKernel vao_spiral_kernel(int n) {
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  std::vector<DiskPoint> points;
  for (int i = 0; i < n; ++i) {
    const double rho = std::sqrt((i + 0.5) / n), phi = golden * i;
    points.push_back({float(rho * std::cos(phi)), float(rho * std::sin(phi))});
  }
  return vao_kernel(points);
}

VaoKernel rotated(const VaoKernel& k, float angle) {
  VaoKernel out = k;
  const double c = std::cos(double(angle)), s = std::sin(double(angle));
  for (int i = 0; i < k.size(); ++i) {
    out.x[std::size_t(i)] = float(c * k.x[std::size_t(i)] - s * k.y[std::size_t(i)]);
    out.y[std::size_t(i)] = float(s * k.x[std::size_t(i)] + c * k.y[std::size_t(i)]);
  }
  return out;
}

void vao_random_rotation(const VaoKernel& base, std::uint32_t seed, int x, int y, VaoKernel& out) {
  const float angle = float(2.0 * std::numbers::pi) * pixel_random(seed, x, y, 0);
  const float ca = std::cos(angle), sa = std::sin(angle);
  out.x.resize(base.x.size());
  out.y.resize(base.y.size());
  out.h = base.h;
  for (std::size_t i = 0; i < base.x.size(); ++i) {
    out.x[i] = ca * base.x[i] - sa * base.y[i];
    out.y[i] = sa * base.x[i] + ca * base.y[i];
  }
}

double vao_eq2_normaliser(const VaoKernel& k, double radius) {
  double sum = 0.0;
  for (float h : k.h) sum += h;
  return radius * sum;
}

VaoCase vao_case(const VaoPipe& pipe, float surface_depth, float tolerance) {
  if (!(surface_depth < pipe.back - tolerance)) return VaoCase::B;  // NaN: background
  if (surface_depth <= pipe.front) return VaoCase::C;
  return VaoCase::A;
}

float vao_unoccluded_length(const VaoPipe& pipe, float surface_depth, float tolerance,
                            bool range_check, float radius) {
  const float full = pipe.back - pipe.front;
  float open;
  switch (vao_case(pipe, surface_depth, tolerance)) {
    case VaoCase::B:
      return full;
    case VaoCase::C:
      open = 0.0f;
      break;
    default:
      open = surface_depth - pipe.front;
      break;
  }
  if (!range_check) return open;
  // §4.4: the occluded part is weighted by s(d), d = how far the sample point (the middle of
  // the pipe) lies behind the surface.
  const float behind = 0.5f * (pipe.front + pipe.back) - surface_depth;
  const float s = behind > 0.0f ? vao_range_falloff(behind, radius) : 1.0f;
  return full - (full - open) * s;
}

VaoFrame vao_frame(const GBuffer& g, bool with_color, int threads) {
  VaoFrame f;
  f.width = g.width();
  f.height = g.height();
  f.camera = g.camera;
  f.depth = depth_with_background_as_nan(g, threads);
  f.normals = prepared_normals(g, threads);
  if (with_color && g.has_color()) {
    f.color = Image(f.width, f.height, 3);
    parallel_for_rows(f.height, threads, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < f.width; ++x)
          for (int c = 0; c < 3; ++c) {
            const float v = g.color(x, y, c);
            f.color(x, y, c) = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
          }
    });
  }
  return f;
}

namespace {

// The tangent sphere of P (§3), radius r = R/2 and centre C = P + r·n, as every sample of the
// pixel sees it. In double: R goes up to 1e30, and float's b² (b ~ r) overflows beyond 1e19
// while its rounding of P + r·n loses P beyond ~1e7 times the depth.
struct Sphere {
  double r;
  glm::dvec3 c;
  double dc, inv_dc;  // C's depth and its inverse
  double c_term;      // |C|² − r² = |P|² + 2r P·n
  // What rounding the float inputs P and n (relative 2^-24) moves c_term and b = v·C by,
  // over 2^-24 and per unit |v| for b.
  double c_term_error, b_error;
  double inv_fx, inv_fy;  // of the camera, for the texels' view rays
};

// One sample's pipe through the sphere, its full length and the depth tolerance of its test.
struct SamplePipe {
  VaoPipe pipe;
  float full, tolerance;
};

// The view ray X = δ v through the centre of texel (ix, iy) meets |X − C| = r at
// δ = (b ± sqrt(b² − a·c_term))/a, a = |v|², b = v·C; δ is planar depth. False if the ray
// misses the sphere in front of the camera (no pipe). The two roots are formed without
// cancellation (their product is c_term/a): for b < 0 the far one is −c_term/(sq − b), which
// is where a ray from a camera inside a huge sphere leaves it through the tangent plane.
bool view_ray_pipe(const CameraIntrinsics& cam, const Sphere& sp, int ix, int iy, float ds,
                   SamplePipe& out) {
  const glm::dvec3 v((double(ix) + 0.5 - cam.cx) * sp.inv_fx,
                     -(double(iy) + 0.5 - cam.cy) * sp.inv_fy, -1.0);
  const double a = glm::dot(v, v), b = glm::dot(v, sp.c);
  const double disc = b * b - a * sp.c_term;
  if (!(disc > 0.0)) return false;
  const double sq = std::sqrt(disc);
  double back, front, tolerance;
  if (b >= 0.0) {
    const double s = b + sq, inv_a = 1.0 / a;
    back = s * inv_a;
    front = sp.c_term / s;
    // Rounding of b, c_term (and of P and n in them) moves δ by ~ε (|b| + sq + (b² +
    // |a c_term|)/sq)/a: ill-conditioned for rays grazing the sphere (small sq).
    tolerance = std::abs(ds) + (b + sq + (b * b + std::abs(a * sp.c_term)) / sq) * inv_a;
  } else {
    const double t = sq - b;  // > 0
    back = -sp.c_term / t;
    front = -t / a;
    // back = −c_term/t: its relative error is c_term's plus t's (t = sq + |b|, moved by at
    // most twice b's error plus sqrt's share of c_term's); both grow where the ray or the
    // view of P grazes the tangent plane.
    const double b_error = sp.b_error * std::sqrt(a);
    tolerance = std::abs(ds) + std::abs(back) * (sp.c_term_error / std::abs(sp.c_term) +
                                                 (2.0 * b_error + a * sp.c_term_error / sq) / t);
  }
  if (!(back > 0.0) || !std::isfinite(back)) return false;
  front = std::max(0.0, front);  // the camera may be inside
  out.pipe.back = float(back);
  out.pipe.front = float(front);
  out.full = float(back - front);
  out.tolerance = float(std::min(double(kFloatEpsilon) * kVaoDepthUlps * tolerance, 1e38));
  return true;
}

// Eq. 5 for the sample point at offset (ox, oy) on the disc, over texel (ix, iy):
// c(x) = max(0, (x − p)·n/|x − p|) (1 − |x − p|/radius)², added as lerp(white, colour, c).
void add_bleeding(const VaoFrame& f, const glm::vec3& nrm, float r, float ox, float oy,
                  float inv_radius, int ix, int iy, VaoPixelSums& out) {
  const glm::vec3 to_sample = r * nrm + glm::vec3(ox, oy, 0.0f);
  const float len = glm::length(to_sample);
  const float cosine = len > 0.0f ? std::max(0.0f, glm::dot(to_sample, nrm) / len) : 0.0f;
  const float fall = std::max(0.0f, 1.0f - len * inv_radius);
  const float weight = cosine * fall * fall;
  const float* col = f.color.data() + 3 * (std::size_t(iy) * f.width + ix);
  for (int k = 0; k < 3; ++k) out.bleed[k] += 1.0f + weight * (col[k] - 1.0f);
  ++out.bleed_count;
}

}  // namespace

VaoPixelSums vao_pixel(const VaoFrame& f, const VaoPixelOptions& o, int x, int y, const float* sx,
                       const float* sy, const float* sh, int n_samples) {
  VaoPixelSums out;
  const int w = f.width, h = f.height;
  const std::size_t idx = std::size_t(y) * w + x;
  const float d = f.depth[idx];
  const glm::vec3 nrm(f.normals.data()[3 * idx], f.normals.data()[3 * idx + 1],
                      f.normals.data()[3 * idx + 2]);
  const CameraIntrinsics& cam = f.camera;
  const glm::dvec3 v0((double(x) + 0.5 - cam.cx) / cam.fx, -(double(y) + 0.5 - cam.cy) / cam.fy,
                      -1.0);
  const glm::dvec3 n(nrm);
  const glm::dvec3 p = double(d) * v0;
  Sphere sp;
  sp.r = 0.5 * double(o.radius);  // the tangent sphere (§3)
  sp.c = p + sp.r * n;
  sp.dc = -sp.c.z;
  if (!(sp.dc > 0.0) || !std::isfinite(sp.dc)) return out;  // the disc is not in front
  sp.inv_dc = 1.0 / sp.dc;
  sp.inv_fx = 1.0 / cam.fx;
  sp.inv_fy = 1.0 / cam.fy;
  // |C|² - r² = |P|² + 2r P·n, without forming r² (no cancellation).
  const double p_len = glm::length(p);
  sp.c_term = glm::dot(p, p) + 2.0 * sp.r * glm::dot(p, n);
  sp.c_term_error = p_len * p_len + 4.0 * sp.r * p_len;
  sp.b_error = p_len + 2.0 * sp.r;
  const float r = float(sp.r), inv_radius = 1.0f / o.radius;

  for (int i = 0; i < n_samples; ++i) {
    const double ox = sp.r * sx[i], oy = sp.r * sy[i];
    const double px = cam.cx + cam.fx * (sp.c.x + ox) * sp.inv_dc;
    const double py = cam.cy - cam.fy * (sp.c.y + oy) * sp.inv_dc;
    // Off-screen samples carry no information: left out (the test also rejects NaN).
    if (!(px >= 0.0 && px < double(w) && py >= 0.0 && py < double(h))) continue;
    const int ix = int(px), iy = int(py);
    const float ds = f.depth[std::size_t(iy) * w + ix];
    SamplePipe sample;
    if (o.view_ray_pipes) {
      if (!view_ray_pipe(cam, sp, ix, iy, ds, sample)) continue;
    } else {
      const double half = sp.r * sh[i];  // half the pipe parallel to the view axis
      sample.pipe = {float(sp.dc - half), float(sp.dc + half)};
      sample.full = float(2.0 * half);  // Σ full = R Σ h_i: F of eq. 2
      sample.tolerance = float(double(kFloatEpsilon) * kVaoDepthUlps * (std::abs(ds) + d + sp.r));
    }
    if (!(sample.full > 0.0f)) continue;
    float open;
    if ((ix == x && iy == y) || vao_case(sample.pipe, ds, sample.tolerance) == VaoCase::B) {
      open = sample.full;  // case B; on P's own texel the surface is P, where the sphere touches
    } else {
      open = std::min(sample.full, vao_unoccluded_length(sample.pipe, ds, sample.tolerance,
                                                         o.range_check, o.radius));
    }
    out.open += open;
    out.full += sample.full;
    if (o.bleeding_step > 0 && i % o.bleeding_step == 0 && ds == ds)
      add_bleeding(f, nrm, r, float(ox), float(oy), inv_radius, ix, iy, out);
  }
  return out;
}

}  // namespace aolab
