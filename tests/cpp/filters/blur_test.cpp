#include "core/filters/blur.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace aolab {
namespace {

struct Flat {
  Image depth;
  GBuffer g;
  explicit Flat(int w = 9, int h = 7) : depth(w, h, 1, 2.0f) {
    g.depth = depth.view();
    g.camera = {10, 10, 0.5f * float(w), 0.5f * float(h)};
  }
};

TEST(GaussianBlur, ConstantStaysConstant) {
  Flat f;
  Image ao(9, 7, 1, 0.625f);
  const Image out = gaussian_blur(ao.view(), f.g, {});
  for (float v : out.pixels()) EXPECT_FLOAT_EQ(v, 0.625f);
}

TEST(GaussianBlur, PreservesMeanOfImpulseAwayFromBorders) {
  Flat f(15, 15);  // the impulse's 5x5 footprint and its taps stay inside the image
  Image ao(15, 15, 1, 0.0f);
  ao(7, 7) = 1.0f;
  BlurSettings s;
  s.sigma = 1.0f;
  s.taps = 5;
  const Image out = gaussian_blur(ao.view(), f.g, s);
  double sum = 0;
  for (float v : out.pixels()) sum += v;
  EXPECT_NEAR(sum, 1.0, 1e-5);
  EXPECT_GT(out(7, 7), out(8, 7));
  EXPECT_FLOAT_EQ(out(8, 7), out(6, 7));  // symmetric
  EXPECT_EQ(out(10, 7), 0.0f);            // 5 taps reach ±2 only
}

TEST(GaussianBlur, BackgroundNeitherContributesNorChanges) {
  Flat f;
  for (int y = 0; y < 7; ++y) f.depth(0, y) = 1e10f;  // left column background
  Image ao(9, 7, 1, 0.5f);
  for (int y = 0; y < 7; ++y) ao(0, y) = 1.0f;
  const Image out = gaussian_blur(ao.view(), f.g, {});
  for (int y = 0; y < 7; ++y) {
    EXPECT_EQ(out(0, y), 1.0f);
    EXPECT_FLOAT_EQ(out(1, y), 0.5f);
  }
}

// The filter as its definition reads, pixel by pixel: the textbook version the row-vectorised
// passes are checked against.
Image blur_by_definition(const Image& ao, const GBuffer& g, const BlurSettings& s) {
  const int w = ao.width(), h = ao.height(), half = s.taps / 2;
  std::vector<float> weights(s.taps);
  for (int i = -half; i <= half; ++i)
    weights[i + half] = std::exp(-0.5f * float(i * i) / (s.sigma * s.sigma));
  Image tmp(w, h, 1), out(w, h, 1);
  auto pass = [&](const Image& src, Image& dst, int dx, int dy) {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (!g.valid(x, y)) {
          dst(x, y) = src(x, y);
          continue;
        }
        float sum = 0.0f, wsum = 0.0f;
        for (int i = -half; i <= half; ++i) {
          const int xx = x + i * dx, yy = y + i * dy;
          if (xx < 0 || yy < 0 || xx >= w || yy >= h || !g.valid(xx, yy)) continue;
          sum += weights[i + half] * src(xx, yy);
          wsum += weights[i + half];
        }
        dst(x, y) = sum / wsum;
      }
  };
  pass(ao, tmp, 1, 0);
  pass(tmp, out, 0, 1);
  return out;
}

// Bit for bit the definition, with background (and NaN AO there) scattered over the frame, at
// sizes smaller than the kernel and larger, for several tap counts and thread counts.
TEST(GaussianBlur, EqualsTheDefinitionBitForBit) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (auto [w, h] : {std::pair{1, 1}, std::pair{3, 2}, std::pair{37, 23}, std::pair{130, 9}}) {
    Flat f(w, h);
    Image ao(w, h, 1);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        ao(x, y) = float((x * 7 + y * 13) % 17) / 16.0f;
        if ((x * 3 + y * 5) % 11 == 0) {
          f.depth(x, y) = nan;  // background: never a tap, keeps its own value
          ao(x, y) = (x + y) % 2 ? nan : 1.0f;
        }
      }
    for (int taps : {1, 5, 9, 31}) {
      BlurSettings s;
      s.taps = taps;
      s.sigma = 0.4f * float(taps);
      const Image want = blur_by_definition(ao, f.g, s);
      for (int threads : {1, 2, 3}) {
        const Image got = gaussian_blur(ao.view(), f.g, s, threads);
        for (int y = 0; y < h; ++y)
          for (int x = 0; x < w; ++x)
            ASSERT_EQ(std::bit_cast<std::uint32_t>(got(x, y)),
                      std::bit_cast<std::uint32_t>(want(x, y)))
                << w << "x" << h << " taps " << taps << " threads " << threads << " at " << x << ","
                << y;
      }
    }
  }
}

TEST(GaussianBlur, RejectsEvenTapsAndBadSigma) {
  Flat f;
  Image ao(9, 7, 1, 0.5f);
  BlurSettings s;
  s.taps = 4;
  EXPECT_THROW(gaussian_blur(ao.view(), f.g, s), std::invalid_argument);
  s = {};
  s.sigma = 0.0f;
  EXPECT_THROW(gaussian_blur(ao.view(), f.g, s), std::invalid_argument);
  Image wrong(8, 7, 1, 0.5f);
  EXPECT_THROW(gaussian_blur(wrong.view(), f.g, {}), std::invalid_argument);
}

}  // namespace
}  // namespace aolab
