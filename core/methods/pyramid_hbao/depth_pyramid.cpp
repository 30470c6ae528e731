#include "core/methods/pyramid_hbao/depth_pyramid.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/base/check.h"
#include "core/base/parallel.h"

namespace aolab {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

void validate_shape(int width, int height, int reduction, int levels) {
  if (reduction < 2 || reduction > 64) throw_invalid("reduction", "must be in [2, 64]", reduction);
  if (levels < 0) throw_invalid("levels", "must be >= 0 (0 = down to 1x1)", levels);
  if (width > kDepthPyramidMaxSide || height > kDepthPyramidMaxSide)
    throw_invalid("depth",
                  "must have sides of at most " + std::to_string(kDepthPyramidMaxSide) + " px",
                  std::to_string(width) + "x" + std::to_string(height));
}

// Level 0: the depth buffer itself, each texel's centroid its pixel centre.
DepthPyramidLevel level_zero(int width, int height) {
  DepthPyramidLevel level;
  level.width = width;
  level.height = height;
  level.scale = 1;
  level.texels.resize(std::size_t(width) * std::size_t(height));
  return level;
}

// The G-buffer's depth, background as NaN, once the G-buffer is known to be valid.
Buffer<float> validated_depth(const GBuffer& g, int threads) {
  g.validate();
  return depth_with_background_as_nan(g, threads);
}

}  // namespace

int DepthPyramid::full_levels(int width, int height, int reduction) {
  validate_shape(width, height, reduction, 0);
  int levels = 1;
  for (int size = std::max(width, height); size > 1; size = (size + reduction - 1) / reduction)
    ++levels;
  return levels;
}

DepthPyramid::DepthPyramid(const GBuffer& g, int reduction, int levels, int threads)
    : DepthPyramid(validated_depth(g, threads), g.width(), g.height(), reduction, levels, threads) {
}

DepthPyramid::DepthPyramid(std::span<const float> depth, int width, int height, int reduction,
                           int levels, int threads)
    : reduction_(reduction) {
  validate_shape(width, height, reduction, levels);
  if (width < 1 || height < 1 || depth.size() != std::size_t(width) * std::size_t(height))
    throw_invalid("depth", "must hold width x height values",
                  std::to_string(depth.size()) + " for " + std::to_string(width) + "x" +
                      std::to_string(height));
  levels_.push_back(level_zero(width, height));
  DepthPyramidLevel& base = levels_.back();
  parallel_for_rows(height, threads, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < width; ++x) {
        const float d = depth[std::size_t(y) * width + x];
        base.texels[std::size_t(y) * width + x] = {std::isfinite(d) && d > 0.0f ? d : kNaN,
                                                   float(x) + 0.5f, float(y) + 0.5f};
      }
  });
  build(levels, threads);
}

void DepthPyramid::build(int levels, int threads) {
  const int full = full_levels(levels_[0].width, levels_[0].height, reduction_);
  const int count = levels == 0 ? full : std::min(levels, full);
  const int k = reduction_;
  levels_.reserve(std::size_t(count));
  while (int(levels_.size()) < count) {
    const DepthPyramidLevel& fine = levels_.back();
    DepthPyramidLevel coarse;
    // §3.3: "The resolution of each subsequent depth pyramid level is K times less
    // (rounded up) on each axis".
    coarse.width = (fine.width + k - 1) / k;
    coarse.height = (fine.height + k - 1) / k;
    coarse.scale = fine.scale * k;
    coarse.texels.resize(std::size_t(coarse.width) * std::size_t(coarse.height));
    parallel_for_rows(coarse.height, threads, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < coarse.width; ++x) {
          // §3.3: the mean of the K×K window of the previous level — here over the children
          // that hold geometry (background never enters a mean) and lie inside the level
          // (the last row and column of a level rounded up have fewer). In double, rounded
          // once, so that a constant stays exactly constant.
          double sum_d = 0, sum_x = 0, sum_y = 0;
          int n = 0;
          const int cy_end = std::min(fine.height, (y + 1) * k);
          const int cx_end = std::min(fine.width, (x + 1) * k);
          for (int cy = y * k; cy < cy_end; ++cy)
            for (int cx = x * k; cx < cx_end; ++cx) {
              const PyramidTexel& c = fine(cx, cy);
              if (!(c.depth == c.depth)) continue;  // background
              sum_d += c.depth, sum_x += c.x, sum_y += c.y;
              ++n;
            }
          PyramidTexel& t = coarse.texels[std::size_t(y) * coarse.width + x];
          if (n == 0) {
            // Background; the centroid is the footprint's centre (never used).
            t = {kNaN, float(double(coarse.scale) * (x + 0.5)),
                 float(double(coarse.scale) * (y + 0.5))};
          } else {
            t = {float(sum_d / n), float(sum_x / n), float(sum_y / n)};
          }
        }
    });
    levels_.push_back(std::move(coarse));
  }
}

}  // namespace aolab
