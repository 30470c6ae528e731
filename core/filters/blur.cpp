#include "core/filters/blur.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace aolab {

namespace {

// One pass of the blur along rows (dx = 1) or columns (dy = 1) over the rows [y0, y1) of dst.
// Each output is Σ w_i·src_i / Σ w_i over the valid taps inside the image, the taps added in
// order i = −half..half, so every value is bit for bit the per-pixel loop's. The loops run over
// x with i outside, on contiguous rows, so that the compiler vectorises them: a tap that is
// invalid or outside the image is selected away (not multiplied by 0, which would turn a NaN
// in src into NaN), and only the edges, where taps leave the image, take the checked path.
void blur_rows(ConstImageView src, MutableImageView dst, ConstImageView valid,
               const std::vector<float>& weights, bool along_rows, int y0, int y1) {
  const int w = src.width, h = src.height, half = int(weights.size()) / 2;
  std::vector<float> sum(w), wsum(w);
  for (int y = y0; y < y1; ++y) {
    std::fill(sum.begin(), sum.end(), 0.0f);
    std::fill(wsum.begin(), wsum.end(), 0.0f);
    for (int i = -half; i <= half; ++i) {
      const float wi = weights[i + half];
      if (along_rows) {
        const float* s = src.row(y);
        const float* v = valid.row(y);
        const int lo = std::max(0, -i), hi = std::min(w, w - i);  // x + i inside [0, w)
        for (int x = lo; x < hi; ++x) {
          const bool ok = v[x + i] != 0.0f;
          sum[x] = ok ? sum[x] + wi * s[x + i] : sum[x];
          wsum[x] = ok ? wsum[x] + wi : wsum[x];
        }
      } else {
        const int yy = y + i;
        if (yy < 0 || yy >= h) continue;
        const float* s = src.row(yy);
        const float* v = valid.row(yy);
        for (int x = 0; x < w; ++x) {
          const bool ok = v[x] != 0.0f;
          sum[x] = ok ? sum[x] + wi * s[x] : sum[x];
          wsum[x] = ok ? wsum[x] + wi : wsum[x];
        }
      }
    }
    const float* s = src.row(y);
    const float* v = valid.row(y);
    float* d = dst.row(y);
    // wsum > 0 wherever the centre tap is valid.
    for (int x = 0; x < w; ++x) d[x] = v[x] != 0.0f ? sum[x] / wsum[x] : s[x];
  }
}

}  // namespace

Image gaussian_blur(ConstImageView ao, const GBuffer& g, const BlurSettings& s, int threads) {
  validate_settings(s, kBlurFields);
  if (s.taps % 2 == 0) throw_invalid("taps", "must be odd", s.taps);
  if (ao.channels != 1) throw_invalid("ao", "must have 1 channel", ao.channels);
  g.validate();
  require_same_size("depth", g.depth, "ao", ao);
  const int w = ao.width, h = ao.height, half = s.taps / 2;
  std::vector<float> weights(s.taps);
  for (int i = -half; i <= half; ++i)
    weights[i + half] = std::exp(-0.5f * float(i * i) / (s.sigma * s.sigma));

  const Image valid = validity_mask(g);
  Image tmp(w, h, 1), out(w, h, 1);
  parallel_for_rows(h, threads, [&](int y0, int y1) {
    blur_rows(ao, tmp.view(), valid.view(), weights, true, y0, y1);
  });
  parallel_for_rows(h, threads, [&](int y0, int y1) {
    blur_rows(tmp.view(), out.view(), valid.view(), weights, false, y0, y1);
  });
  return out;
}

}  // namespace aolab
