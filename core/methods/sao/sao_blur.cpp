#include "core/methods/sao/sao_blur.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace aolab {

namespace {

// One pass along rows (dx = 1) or columns (dx = 0) from `in` to `out`.
void filter_pass(const float* in, float* out, const float* depth, int w, int h, bool rows,
                 const SaoBlurParams& p, const std::vector<float>& gauss, int threads,
                 Progress* progress) {
  const float inv_edge = p.edge_depth > 0.0f ? 1.0f / p.edge_depth : 0.0f;
  parallel_for_rows(
      h, threads,
      [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
          for (int x = 0; x < w; ++x) {
            const std::size_t c = std::size_t(y) * w + x;
            const float z0 = depth[c];
            if (!(z0 == z0)) {
              out[c] = in[c];  // background keeps its value
              continue;
            }
            // Σ w_j·(A_j − A_0) / Σ w_j added to A_0: the same mean, and a constant image (every
            // difference 0) comes back bit for bit.
            const float a0 = in[c];
            float sum = 0.0f, total = gauss[0];
            for (int j = -p.radius; j <= p.radius; ++j) {
              if (j == 0) continue;
              const int tx = rows ? x + j * p.stride : x, ty = rows ? y : y + j * p.stride;
              if (tx < 0 || tx >= w || ty < 0 || ty >= h) continue;
              const std::size_t t = std::size_t(ty) * w + tx;
              const float z = depth[t];
              if (!(z == z)) continue;  // background never contributes
              // The range weight: linear in the depth difference (§2.4's depth-aware weight).
              const float edge = std::max(0.0f, 1.0f - std::abs(z - z0) * inv_edge);
              const float weight = gauss[std::size_t(std::abs(j))] * edge;
              if (!(weight > 0.0f)) continue;
              sum += weight * (in[t] - a0);
              total += weight;
            }
            out[c] = a0 + sum / total;  // total ≥ gauss[0] = 1
          }
      },
      progress);
}

}  // namespace

void sao_bilateral_filter(Image& ao, std::span<const float> depth, const SaoBlurParams& p,
                          int threads, Progress* progress) {
  const int w = ao.width(), h = ao.height();
  std::vector<float> gauss(std::size_t(p.radius) + 1);
  for (int j = 0; j <= p.radius; ++j)
    gauss[std::size_t(j)] = float(std::exp(-double(j) * j / (2.0 * double(p.sigma) * p.sigma)));
  Buffer<float> tmp(std::size_t(w) * std::size_t(h));
  filter_pass(ao.data(), tmp.data(), depth.data(), w, h, true, p, gauss, threads, progress);
  filter_pass(tmp.data(), ao.data(), depth.data(), w, h, false, p, gauss, threads, progress);
}

}  // namespace aolab
