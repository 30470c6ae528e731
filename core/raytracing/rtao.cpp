#include "core/raytracing/rtao.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/base/check.h"
#include "core/sampling/cosine_hemisphere.h"

namespace aolab {

namespace {

// The pixel centre's camera ray at depth d (docs/conventions.md), in double.
glm::dvec3 pixel_point(const CameraIntrinsics& cam, int x, int y, double d) {
  return {(x + 0.5 - cam.cx) / cam.fx * d, -(y + 0.5 - cam.cy) / cam.fy * d, -d};
}

// The offset of the pixel whose point is p (rtao.h, kRtaoOffsetPixels): the one formula
// rtao_range and rtao share. `per_pixel` is 1 / min(fx, fy).
RtaoOffset offset_of(int x, int y, const glm::dvec3& p, double per_pixel, double radius,
                     const RayScene& scene) {
  RtaoOffset o;
  o.x = x, o.y = y, o.depth = -p.z;
  o.point_distance = glm::length(p);
  o.footprint = kRtaoOffsetPixels * o.depth * per_pixel;
  o.scale = o.point_distance + std::min(scene.camera_distance() + radius + scene.longest_edge(),
                                        scene.coordinate_scale());
  o.epsilon = o.footprint + kRtaoOffsetRounding * o.scale;
  return o;
}

// Whether a ray origin within ε of p may reach the ray tracer's range.
bool beyond_range(const glm::dvec3& p, double eps) {
  for (int c = 0; c < 3; ++c)
    if (!(std::abs(p[c]) + eps < double(kMaxRayCoordinate))) return true;
  return false;
}

// A number for a message's explanation (the value a limit is broken by prints exactly).
std::string short_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

std::string pixel_name(const RtaoOffset& o) {
  return "pixel (" + std::to_string(o.x) + ", " + std::to_string(o.y) + ")";
}

// ε at one pixel with its parts, for the refusal and the warning.
std::string offset_parts(const RtaoRange& r, const RtaoOffset& o) {
  return "at " + pixel_name(o) + ", depth " + short_number(o.depth) +
         ", ε = " + short_number(o.epsilon) + " = " + short_number(100.0 * o.epsilon / r.radius) +
         " % of R: 0.01 px at that depth (" + short_number(o.footprint) +
         ") + 2^-21 of the scale |P| + min(|c| + R + D, L) = " + short_number(o.scale) +
         " (point from the camera |P| = " + short_number(o.point_distance) +
         ", camera from the world origin |c| = " + short_number(r.camera_distance) +
         ", longest triangle edge D = " + short_number(r.longest_edge) +
         ", farthest vertex L = " + short_number(r.coordinate_scale) + ")";
}

std::string of_pixels(std::size_t n, std::size_t total) {
  return std::to_string(n) + " of " + std::to_string(total) + " pixels";
}

// Working memory of one band of rows: the directions of a pixel's rays (x, y, z apart, as
// Embree's packets hold them) and which of them are blocked.
struct Scratch {
  std::vector<float> dx, dy, dz;
  std::unique_ptr<bool[]> blocked;
};

}  // namespace

std::string RtaoRange::refusal() const {
  if (beyond > 0)
    return "depth must put every point rays are traced from inside the ray tracer's range "
           "(coordinates below " +
           detail::exact_number(kMaxRayCoordinate) +
           " in magnitude, Embree's FLT_LARGE): " + of_pixels(beyond, pixels) +
           " are beyond it, the first at " + pixel_name(first_beyond) + ", got " +
           detail::exact_number(float(first_beyond.depth));
  if (refused > 0)
    return "radius must exceed the ray offset ε on every pixel rays are traced from, as "
           "occluders nearer than ε to a surface are lost (docs/conventions.md, \"Ranges\"), but "
           "ε ≥ R on " +
           of_pixels(refused, pixels) + "; the largest is " + offset_parts(*this, largest) +
           "; raise R, move the scene and its camera nearer the world origin, subdivide long "
           "triangles or render more pixels, got " +
           detail::exact_number(float(radius));
  return "";
}

std::string RtaoRange::warning() const {
  if (warned == 0 || !refusal().empty()) return "";
  return "rtao: the ray offset ε exceeds " + short_number(100.0 * kRtaoOffsetWarning) +
         " % of R = " + short_number(radius) + " on " + of_pixels(warned, pixels) +
         ", where occluders nearer than ε to a surface are lost (docs/conventions.md, "
         "\"Ranges\"); the largest is " +
         offset_parts(*this, largest);
}

RtaoRange rtao_range(const GBuffer& g, const RayScene& scene, float radius, int threads) {
  RtaoSettings checked;
  checked.radius = radius;
  validate_settings(checked, kRtaoFields);
  g.validate();
  RtaoRange range;
  range.radius = radius;
  range.camera_distance = scene.camera_distance();
  range.longest_edge = scene.longest_edge();
  range.coordinate_scale = scene.coordinate_scale();
  if (scene.triangle_count() == 0) return range;  // no ray is traced
  const double per_pixel = 1.0 / std::min(double(g.camera.fx), double(g.camera.fy));
  // Each row apart, then merged in row order: the same answer for any thread count.
  std::vector<RtaoRange> rows(std::size_t(g.height()));
  parallel_for_rows(g.height(), resolve_threads(threads), [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      RtaoRange& row = rows[std::size_t(y)];
      for (int x = 0; x < g.width(); ++x) {
        if (!g.valid(x, y)) continue;
        const glm::dvec3 p = pixel_point(g.camera, x, y, g.depth(x, y));
        const RtaoOffset o = offset_of(x, y, p, per_pixel, radius, scene);
        ++row.pixels;
        row.warned += o.epsilon > kRtaoOffsetWarning * radius;
        row.refused += o.epsilon >= radius;
        if (beyond_range(p, o.epsilon) && row.beyond++ == 0) row.first_beyond = o;
        if (row.largest.x < 0 || o.epsilon > row.largest.epsilon) row.largest = o;
      }
    }
  });
  for (const RtaoRange& row : rows) {
    if (row.pixels == 0) continue;
    if (range.beyond == 0 && row.beyond > 0) range.first_beyond = row.first_beyond;
    if (range.pixels == 0 || row.largest.epsilon > range.largest.epsilon)
      range.largest = row.largest;
    range.pixels += row.pixels, range.warned += row.warned, range.refused += row.refused,
        range.beyond += row.beyond;
  }
  return range;
}

Image rtao(const GBuffer& g, const RayScene& scene, const RtaoSettings& s,
           const RunOptions& options, RtaoRange* range_out) {
  validate_settings(s, kRtaoFields);
  g.validate();
  require_normal(g, "rtao");
  const RtaoRange range = rtao_range(g, scene, s.radius, options.threads);
  if (range_out) *range_out = range;
  const std::string refusal = range.refusal();
  if (!refusal.empty()) throw std::invalid_argument(refusal);
  const int w = g.width(), h = g.height();
  const int threads = resolve_threads(options.threads);
  const Image normals = prepared_normals(g, threads);
  const CameraIntrinsics cam = g.camera;
  const double per_pixel = 1.0 / std::min(double(cam.fx), double(cam.fy));
  const auto seed = std::uint32_t(s.seed);
  const float t_far = s.radius;
  const int n_rays = s.rays;
  const CosineStrata strata(n_rays);
  const std::size_t padded = strata.column.size();
  const bool empty = scene.triangle_count() == 0;

  return image_from_pixels(
      w, h, threads, options.progress,
      [&] {
        Scratch sc;
        sc.dx.resize(padded);
        sc.dy.resize(padded);
        sc.dz.resize(padded);
        sc.blocked = std::make_unique<bool[]>(padded);
        return sc;
      },
      [&](Scratch& sc, int x, int y) -> float {
        if (!g.valid(x, y) || empty) return 1.0f;
        const glm::dvec3 p = pixel_point(cam, x, y, g.depth(x, y));
        const glm::vec3 n(normals(x, y, 0), normals(x, y, 1), normals(x, y, 2));
        const double eps = offset_of(x, y, p, per_pixel, s.radius, scene).epsilon;
        const glm::dvec3 o = p + eps * glm::dvec3(n);
        const float origin[3] = {float(o.x), float(o.y), float(o.z)};
        // The rays of for_each_cosine_ray<float>, drawn a vector at a time: drawn one by one,
        // they cost half as much as Embree's traversal of them.
        cosine_directions(strata, pixel_hash(seed, x, y), n, sc.dx.data(), sc.dy.data(),
                          sc.dz.data());
        scene.occluded_from(origin, sc.dx.data(), sc.dy.data(), sc.dz.data(), n_rays, t_far,
                            sc.blocked.get());
        double blocked = 0.0;
        for (int i = 0; i < n_rays; ++i)
          if (sc.blocked[std::size_t(i)]) blocked += strata.weight[std::size_t(i)];
        return float(std::clamp(1.0 - blocked, 0.0, 1.0));
      });
}

std::vector<SettingDescription> rtao_setting_descriptions() {
  return describe_settings(kRtaoFields);
}

}  // namespace aolab
