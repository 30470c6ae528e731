#include "core/methods/sao/sao.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>
#include <vector>

#include "core/base/parallel.h"
#include "core/methods/sao/sao_blur.h"
#include "core/methods/sao/sao_shared.h"
#include "core/sampling/random.h"

namespace aolab {

std::vector<SaoZLevel> sao_z_pyramid(std::span<const float> depth, int width, int height,
                                     int max_level, SaoGrid grid, int threads) {
  std::vector<SaoZLevel> levels(std::size_t(max_level) + 1);
  SaoZLevel& base = levels[0];
  base.width = width;
  base.height = height;
  base.depth.assign(depth.begin(), depth.end());
  base.source.resize(depth.size());
  for (std::size_t i = 0; i < depth.size(); ++i) base.source[i] = std::int32_t(i);
  // §2.2: z_{m+1}(x, y) = z_m(2x + ((y & 1) ⊕ 1), 2y + ((x & 1) ⊕ 1)), a rotated grid that
  // favours neither axis; the reference code's minify shader drops the ⊕ 1 (SaoGrid).
  const int flip = grid == SaoGrid::Paper ? 1 : 0;
  for (int m = 1; m <= max_level; ++m) {
    const SaoZLevel& fine = levels[std::size_t(m) - 1];
    SaoZLevel& coarse = levels[std::size_t(m)];
    coarse.width = (fine.width + 1) / 2;
    coarse.height = (fine.height + 1) / 2;
    const std::size_t n = std::size_t(coarse.width) * std::size_t(coarse.height);
    coarse.depth.resize(n);
    coarse.source.resize(n);
    parallel_for_rows(coarse.height, threads, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < coarse.width; ++x) {
          const int fx = std::min(2 * x + ((y & 1) ^ flip), fine.width - 1);
          const int fy = std::min(2 * y + ((x & 1) ^ flip), fine.height - 1);
          const std::size_t from = std::size_t(fy) * fine.width + fx;
          const std::size_t to = std::size_t(y) * coarse.width + x;
          coarse.depth[to] = fine.depth[from];
          coarse.source[to] = fine.source[from];
        }
    });
  }
  return levels;
}

Image sao_quad_normals(const GBuffer& g, std::span<const float> depth, ConstImageView fallback,
                       int threads) {
  const int w = g.width(), h = g.height();
  const CameraIntrinsics& cam = g.camera;
  Image out(w, h, 3, 0.0f);
  // View-space position of pixel (x, y)'s centre at its depth, in double.
  const auto position = [&](int x, int y) {
    const double d = depth[std::size_t(y) * w + x];
    return glm::dvec3((x + 0.5 - cam.cx) * d / cam.fx, -(y + 0.5 - cam.cy) * d / cam.fy, -d);
  };
  // The quad partner of i along an axis of n pixels: i ^ 1 (the GPU's 2×2 quad derivative),
  // or i's other neighbour where i ^ 1 leaves the image. Returns (lo, hi), lo < hi.
  const auto pair = [](int i, int n, int& lo, int& hi) {
    int j = i ^ 1;
    if (j >= n) j = i - 1;
    lo = std::min(i, j);
    hi = std::max(i, j);
    return j >= 0;
  };
  parallel_for_rows(h, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t idx = std::size_t(y) * w + x;
        if (!(depth[idx] == depth[idx])) continue;  // background keeps (0, 0, 0)
        int x0, x1, y0_, y1_;
        glm::dvec3 n(0.0);
        if (pair(x, w, x0, x1) && pair(y, h, y0_, y1_)) {
          const float dx0 = depth[std::size_t(y) * w + x0], dx1 = depth[std::size_t(y) * w + x1];
          const float dy0 = depth[std::size_t(y0_) * w + x], dy1 = depth[std::size_t(y1_) * w + x];
          if (dx0 == dx0 && dx1 == dx1 && dy0 == dy0 && dy1 == dy1)
            n = glm::cross(position(x1, y) - position(x0, y), position(x, y0_) - position(x, y1_));
        }
        const double len = glm::length(n);
        if (!(len > 0.0) || !std::isfinite(len)) {
          for (int c = 0; c < 3; ++c) out(x, y, c) = fallback(x, y, c);
          continue;
        }
        n /= len;
        if (glm::dot(n, position(x, y)) > 0.0) n = -n;  // face the camera (n·(−P) ≥ 0)
        for (int c = 0; c < 3; ++c) out(x, y, c) = float(n[c]);
      }
  });
  return out;
}

namespace {

struct Frame {
  const std::vector<SaoZLevel>* levels;
  const float* normals;  // 3 per pixel
  int width, height;
  CameraIntrinsics cam;
};

float sao_pixel(const Frame& f, const SaoSettings& s, const SpiralTaps& taps,
                const ObscuranceEstimator& e, int x, int y) {
  const std::vector<SaoZLevel>& levels = *f.levels;
  const std::size_t idx = std::size_t(y) * f.width + x;
  const float d = levels[0].depth[idx];
  if (!(d == d)) return 1.0f;  // background
  const glm::vec3 n(f.normals[3 * idx], f.normals[3 * idx + 1], f.normals[3 * idx + 2]);
  const double bias = double(s.bias) * double(s.radius);  // a constant distance, β·r
  // h_i = α_i·r' (§2.3), r' the larger axis of the projected disc.
  const float r_max = s.radius * std::max(f.cam.fx, f.cam.fy) / d;
  const int max_level = int(levels.size()) - 1;
  const bool at_source = s.tap_position == int(SaoTapPosition::Source);
  return obscurance_estimate(
      f.cam, x, y, d, n, s.radius, s.random_rotation, s.seed, bias, taps, e, f.width, f.height,
      [&](int i, int& sx, int& sy, float& ds) {
        // m_i = clamp(⌊log2 h_i⌋ − q', 0, L_max) (§2.3); ilogb reads ⌊log2⌋ off the exponent.
        const float h_i = taps.alpha(i) * r_max;
        const int level =
            h_i >= 1.0f ? std::clamp(std::ilogb(h_i) - s.log_max_offset, 0, max_level) : 0;
        const SaoZLevel& lv = levels[std::size_t(level)];
        const int mx = std::min(sx >> level, lv.width - 1);
        const int my = std::min(sy >> level, lv.height - 1);
        const std::size_t t = std::size_t(my) * lv.width + mx;
        ds = lv.depth[t];
        if (at_source) {  // the pixel the texel was subsampled from (SaoTapPosition)
          sx = int(lv.source[t] % f.width);
          sy = int(lv.source[t] / f.width);
        }
        return ds == ds;
      });
}

}  // namespace

Image sao(const GBuffer& g, const SaoSettings& s, const RunOptions& options) {
  g.validate();
  require_normal(g, "sao");
  validate_settings(s, kSaoFields);
  const int w = g.width(), h = g.height();
  const int threads = resolve_threads(options.threads);
  // Rows to do: the estimate's (obscurance_simd counts its own) and the filter's two passes.
  const bool simd = options.kernel == Kernel::Simd;
  if (options.progress)
    options.progress->total += (simd ? 0 : h) + (s.filter ? 2 * std::int64_t(h) : 0);

  const Buffer<float> depth = depth_with_background_as_nan(g, threads);
  Image normals = prepared_normals(g, threads);
  if (s.normals == int(SaoNormals::Depth))
    normals = sao_quad_normals(g, depth, normals.view(), threads);
  const SpiralTaps taps(s.samples, s.turns);
  const ObscuranceEstimator e(s.radius, s.samples, s.intensity, s.epsilon, s.contrast, s.falloff);
  SaoBlurParams b;
  b.radius = s.filter_radius;
  b.stride = s.filter_stride;
  b.sigma = s.filter_sigma;
  const double edge = double(kSaoFilterEdgeDepth) * s.radius / s.edge_sharpness;
  b.edge_depth = s.edge_sharpness > 0.0f
                     ? float(std::clamp(edge, double(std::numeric_limits<float>::min()),
                                        double(std::numeric_limits<float>::max())))
                     : 0.0f;

  if (simd) {
    ObscuranceLevels levels =
        sao_levels_for_simd(depth, w, h, s.max_mip_level, SaoGrid(s.grid),
                            s.tap_position == int(SaoTapPosition::Source), threads);
    levels.r_max_scale = s.radius * std::max(g.camera.fx, g.camera.fy);
    levels.log_max_offset = s.log_max_offset;
    // b = β·r, a constant distance: β in units of r.
    const ObscuranceSimdFrame sf{
        depth.data(), normals.data(), w,      h,     g.camera, s.radius, s.random_rotation,
        s.seed,       0.0f,           s.bias, &taps, &e,       &levels};
    Image out = obscurance_simd(sf, threads, options.progress);
    if (s.filter) sao_bilateral_filter_simd(out, depth, b, threads, options.progress);
    return out;
  }

  const std::vector<SaoZLevel> levels =
      sao_z_pyramid(depth, w, h, s.max_mip_level, SaoGrid(s.grid), threads);
  const Frame frame{&levels, normals.data(), w, h, g.camera};

  Image out(w, h, 1, 1.0f);
  parallel_for_rows(
      h, threads,
      [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
          for (int x = 0; x < w; ++x) out(x, y) = sao_pixel(frame, s, taps, e, x, y);
      },
      options.progress);
  if (s.filter) {
    sao_bilateral_filter(out, depth, b, threads, options.progress);
    for (float& v : out.pixels()) v = std::clamp(v, 0.0f, 1.0f);  // a mean in [0, 1], rounded
  }
  return out;
}

Method sao_method() {
  Method m =
      registered_method("sao", "Scalable ambient obscurance",
                        "McGuire, Mara, Luebke 2012, Scalable Ambient Obscurance", kSaoFields, sao);
  m.needs_normal = true;
  m.has_simd_kernel = true;
  return m;
}

}  // namespace aolab
