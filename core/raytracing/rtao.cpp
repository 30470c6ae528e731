#include "core/raytracing/rtao.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "core/sampling/cosine_hemisphere.h"

namespace aolab {

namespace {

// Working memory of one band of rows: the directions of a pixel's rays (x, y, z apart, as
// Embree's packets hold them) and which of them are blocked.
struct Scratch {
  std::vector<float> dx, dy, dz;
  std::unique_ptr<bool[]> blocked;
};

}  // namespace

Image rtao(const GBuffer& g, const RayScene& scene, const RtaoSettings& s,
           const RunOptions& options) {
  validate_settings(s, kRtaoFields);
  g.validate();
  require_normal(g, "rtao");
  const int w = g.width(), h = g.height();
  const int threads = resolve_threads(options.threads);
  const Image normals = prepared_normals(g, threads);
  const CameraIntrinsics cam = g.camera;
  const double footprint = 1.0 / std::min(double(cam.fx), double(cam.fy));
  const double rounding = kRtaoOffsetRounding * scene.coordinate_scale();
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
        const double d = g.depth(x, y);
        // The pixel centre's camera ray at depth d (docs/conventions.md), in double.
        const glm::dvec3 p((x + 0.5 - cam.cx) / cam.fx * d, -(y + 0.5 - cam.cy) / cam.fy * d, -d);
        const glm::vec3 n(normals(x, y, 0), normals(x, y, 1), normals(x, y, 2));
        const double eps = kRtaoOffsetPixels * d * footprint + rounding;
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
