#include "core/filters/blur.h"

#include <gtest/gtest.h>

#include <cmath>

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
