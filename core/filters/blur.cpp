#include "core/filters/blur.h"

#include <cmath>
#include <vector>

namespace aolab {

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

  Image valid = validity_mask(g);
  Image tmp(w, h, 1), out(w, h, 1);
  // One pass along (dx, dy); `src` and `dst` are 1-channel images of the frame's size.
  auto pass = [&](ConstImageView src, Image& dst, int dx, int dy) {
    parallel_for_rows(h, threads, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < w; ++x) {
          if (valid(x, y) == 0.0f) {
            dst(x, y) = src(x, y);
            continue;
          }
          float sum = 0.0f, wsum = 0.0f;
          for (int i = -half; i <= half; ++i) {
            const int xx = x + i * dx, yy = y + i * dy;
            if (xx < 0 || yy < 0 || xx >= w || yy >= h || valid(xx, yy) == 0.0f) continue;
            sum += weights[i + half] * src(xx, yy);
            wsum += weights[i + half];
          }
          dst(x, y) = sum / wsum;  // wsum > 0: the centre tap is valid
        }
    });
  };
  pass(ao, tmp, 1, 0);
  pass(tmp.view(), out, 0, 1);
  return out;
}

}  // namespace aolab
