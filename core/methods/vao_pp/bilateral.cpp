#include "core/methods/vao_pp/bilateral.h"

#include <cmath>
#include <vector>

#include "core/base/check.h"

namespace aolab {

Image cross_bilateral_filter(ConstImageView image, const GBuffer& g, int taps, float sigma,
                             float depth_threshold, int threads, Progress* progress) {
  if (taps < 1 || taps % 2 == 0) throw_invalid("taps", "must be an odd number >= 1", taps);
  if (!(sigma > 0.0f) || !std::isfinite(sigma)) throw_invalid("sigma", "must be > 0", sigma);
  if (!(depth_threshold >= 0.0f)) throw_invalid("depth_threshold", "must be >= 0", depth_threshold);
  require_same_size("depth", g.depth, "image", image);
  const int w = image.width, h = image.height, nc = image.channels, half = taps / 2;
  std::vector<float> weights(static_cast<std::size_t>(taps));
  for (int i = -half; i <= half; ++i)
    weights[std::size_t(i + half)] = std::exp(-0.5f * float(i * i) / (sigma * sigma));
  // Every comparison with a background depth fails.
  const Buffer<float> depth = depth_with_background_as_nan(g, threads);

  Image tmp(w, h, nc), out(w, h, nc);
  auto pass = [&](ConstImageView src, Image& dst, int dx, int dy) {
    parallel_for_rows(
        h, threads,
        [&](int y0, int y1) {
          std::vector<float> sum(static_cast<std::size_t>(nc));
          for (int y = y0; y < y1; ++y)
            for (int x = 0; x < w; ++x) {
              const float dc = depth[std::size_t(y) * w + x];
              if (!(dc == dc)) {
                for (int c = 0; c < nc; ++c) dst(x, y, c) = src(x, y, c);
                continue;
              }
              std::fill(sum.begin(), sum.end(), 0.0f);
              float wsum = 0.0f;
              for (int i = -half; i <= half; ++i) {
                const int xx = x + i * dx, yy = y + i * dy;
                if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
                // §4.6: "we do not take neighbouring pixels with depth variation over a
                // certain pre-defined threshold into account" (NaN fails too).
                if (!(std::abs(depth[std::size_t(yy) * w + xx] - dc) <= depth_threshold)) continue;
                const float wt = weights[std::size_t(i + half)];
                for (int c = 0; c < nc; ++c) sum[std::size_t(c)] += wt * src(xx, yy, c);
                wsum += wt;
              }
              for (int c = 0; c < nc; ++c) dst(x, y, c) = sum[std::size_t(c)] / wsum;
            }
        },
        progress);
  };
  if (progress) progress->total += 2 * h;
  pass(image, tmp, 1, 0);
  pass(tmp.view(), out, 0, 1);
  return out;
}

}  // namespace aolab
