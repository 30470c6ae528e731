// Known answers for core/scoring/ssim.h, and agreement with a direct (non-separable) transcription
// of Wang et al. 2004 eqs. (13)–(16) with scipy's 'reflect' boundary written independently here.
// The scikit-image cross-check is in tests/python/api/test_metrics.py.
#include "core/scoring/ssim.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::random_image;

// 'reflect' by folding, one mirror at a time: a different route to the same index as the
// library's modular formula.
int fold(int i, int n) {
  while (i < 0 || i >= n) i = i < 0 ? -i - 1 : 2 * n - 1 - i;
  return i;
}

// SSIM of pixel (x, y) straight from the definitions, with the 2-D weights w(i)·w(j).
double direct_ssim(const Image& a, const Image& b, int x, int y) {
  const double sigma = 1.5;
  const int r = 5;
  std::vector<double> w;
  double sum = 0;
  for (int i = -r; i <= r; ++i) {
    w.push_back(std::exp(-double(i * i) / (2 * sigma * sigma)));
    sum += w.back();
  }
  double ma = 0, mb = 0;
  for (int j = -r; j <= r; ++j)
    for (int i = -r; i <= r; ++i) {
      const double wt = w[i + r] * w[j + r] / (sum * sum);
      ma += wt * a(fold(x + i, a.width()), fold(y + j, a.height()));
      mb += wt * b(fold(x + i, a.width()), fold(y + j, a.height()));
    }
  double va = 0, vb = 0, cov = 0;
  for (int j = -r; j <= r; ++j)
    for (int i = -r; i <= r; ++i) {
      const double wt = w[i + r] * w[j + r] / (sum * sum);
      const double da = a(fold(x + i, a.width()), fold(y + j, a.height())) - ma;
      const double db = b(fold(x + i, a.width()), fold(y + j, a.height())) - mb;
      va += wt * da * da;
      vb += wt * db * db;
      cov += wt * da * db;
    }
  const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
  return (2 * ma * mb + c1) * (2 * cov + c2) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
}

TEST(Ssim, DefaultConstantsAreWangEtAl) {
  const SsimConstants k = ssim_constants(SsimSettings{});
  EXPECT_EQ(k.radius, 5);  // 11 x 11 window
  EXPECT_DOUBLE_EQ(k.c1, 1e-4);
  EXPECT_DOUBLE_EQ(k.c2, 9e-4);
}

TEST(Ssim, IdenticalImagesGiveOne) {
  const Image a = random_image(23, 17, 1);
  const Image s = ssim_map(a.view(), a.view());
  for (float v : s.pixels()) ASSERT_EQ(v, 1.0f);
  EXPECT_EQ(mean_ssim(a.view(), a.view()), 1.0);
}

TEST(Ssim, ConstantImagesKnownAnswer) {
  // No variance, so the contrast-structure term is C2 / C2 = 1 and S is the luminance term.
  const double p = 0.8, q = 0.3, c1 = 1e-4;
  const Image a(16, 12, 1, float(p)), b(16, 12, 1, float(q));
  const double expected =
      (2 * double(float(p)) * double(float(q)) + c1) /
      (double(float(p)) * double(float(p)) + double(float(q)) * double(float(q)) + c1);
  EXPECT_NEAR(mean_ssim(a.view(), b.view()), expected, 1e-9);
}

TEST(Ssim, SymmetricAndAtMostOne) {
  const Image a = random_image(31, 26, 2);
  const Image b = random_image(31, 26, 3);
  const Image ab = ssim_map(a.view(), b.view());
  const Image ba = ssim_map(b.view(), a.view());
  ASSERT_EQ(ab.pixels().size(), ba.pixels().size());
  EXPECT_EQ(std::memcmp(ab.data(), ba.data(), ab.pixels().size() * sizeof(float)), 0);
  for (float v : ab.pixels()) EXPECT_LE(v, 1.0f);
  EXPECT_EQ(mean_ssim(a.view(), b.view()), mean_ssim(b.view(), a.view()));
  EXPECT_LE(mean_ssim(a.view(), b.view()), 1.0);
}

class SsimDirect : public ::testing::TestWithParam<std::pair<int, int>> {};

TEST_P(SsimDirect, MatchesDirectDefinition) {
  const auto [width, height] = GetParam();
  const Image a = random_image(width, height, 10);
  Image b = random_image(width, height, 11);
  for (std::size_t i = 0; i < b.pixels().size(); ++i)  // correlated, so S spans a real range
    b.pixels()[i] = 0.7f * a.pixels()[i] + 0.3f * b.pixels()[i];
  const Image s = ssim_map(a.view(), b.view());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double expected = direct_ssim(a, b, x, y);
      ASSERT_TRUE(std::isfinite(s(x, y))) << x << ", " << y;
      // The map is float; the two routes agree in double to ~1e-12.
      ASSERT_NEAR(s(x, y), expected, 1e-6) << x << ", " << y;
    }
}

// Includes images smaller than the window (repeated reflection) and a 1 x 1 image.
INSTANTIATE_TEST_SUITE_P(Sizes, SsimDirect,
                         ::testing::Values(std::pair{3, 4}, std::pair{1, 1}, std::pair{2, 7},
                                           std::pair{11, 11}, std::pair{20, 13},
                                           std::pair{37, 29}));

TEST(Ssim, TinyImageAveragesAllPixels) {
  // 3 x 4: no interior at all, so the mean is over every pixel (documented fallback).
  const Image a = random_image(3, 4, 20);
  const Image b = random_image(3, 4, 21);
  const Image s = ssim_map(a.view(), b.view());
  double sum = 0;
  for (float v : s.pixels()) {
    EXPECT_TRUE(std::isfinite(v));
    sum += v;
  }
  const double mean = mean_ssim(a.view(), b.view());
  EXPECT_TRUE(std::isfinite(mean));
  EXPECT_NEAR(mean, sum / 12, 1e-6);
}

TEST(Ssim, MeanIsOverTheInteriorCroppedByFive) {
  const Image a = random_image(24, 19, 30);
  const Image b = random_image(24, 19, 31);
  const Image s = ssim_map(a.view(), b.view());
  double sum = 0;
  int count = 0;
  for (int y = 5; y < 19 - 5; ++y)
    for (int x = 5; x < 24 - 5; ++x) {
      sum += s(x, y);
      ++count;
    }
  EXPECT_NEAR(mean_ssim(a.view(), b.view()), sum / count, 1e-6);  // the map is float
}

TEST(Ssim, MaskedBackgroundCountsAsOne) {
  const Image a = random_image(30, 25, 40);
  Image b = a;
  Image mask(30, 25, 1, 1.0f);
  for (int y = 0; y < 25; ++y)
    for (int x = 0; x < 12; ++x) {
      b(x, y) = 0.0f;  // different, but background
      mask(x, y) = 0.0f;
    }
  // Both images read 1 on the background, so they are identical everywhere.
  EXPECT_EQ(mean_ssim(a.view(), b.view(), mask.view()), 1.0);
  // Without the mask the difference shows.
  EXPECT_LT(mean_ssim(a.view(), b.view()), 0.9);
}

TEST(Ssim, MaskOnlyOnTheBorderAveragesMaskedPixels) {
  const Image a = random_image(20, 20, 50);
  const Image b = random_image(20, 20, 51);
  Image mask(20, 20, 1, 0.0f);
  for (int x = 0; x < 20; ++x) mask(x, 0) = 1.0f;  // top row only: outside the interior
  // Expected: S of the substituted images, averaged over the masked row.
  Image a1(20, 20, 1, 1.0f), b1(20, 20, 1, 1.0f);
  for (int x = 0; x < 20; ++x) {
    a1(x, 0) = a(x, 0);
    b1(x, 0) = b(x, 0);
  }
  const Image s = ssim_map(a1.view(), b1.view());
  double sum = 0;
  for (int x = 0; x < 20; ++x) sum += s(x, 0);
  EXPECT_NEAR(mean_ssim(a.view(), b.view(), mask.view()), sum / 20, 1e-6);
}

TEST(Ssim, BitIdenticalForAnyThreadCount) {
  const Image a = random_image(83, 150, 60);
  const Image b = random_image(83, 150, 61);
  Image mask = random_image(83, 150, 62);
  for (float& v : mask.pixels()) v = v > 0.2f ? 1.0f : 0.0f;
  const Image one = ssim_map(a.view(), b.view(), {}, 1);
  const double mean_one = mean_ssim(a.view(), b.view(), mask.view(), {}, 1);
  for (int threads : {2, 3, 0}) {
    const Image s = ssim_map(a.view(), b.view(), {}, threads);
    EXPECT_EQ(std::memcmp(one.data(), s.data(), one.pixels().size() * sizeof(float)), 0) << threads;
    EXPECT_EQ(mean_ssim(a.view(), b.view(), mask.view(), {}, threads), mean_one) << threads;
  }
}

TEST(Ssim, RejectsBadInput) {
  const Image a(12, 12, 1, 0.5f), small(11, 12, 1, 0.5f), empty_mask(12, 12, 1, 0.0f);
  EXPECT_THROW(ssim_map(a.view(), small.view()), std::invalid_argument);
  EXPECT_THROW(mean_ssim(a.view(), a.view(), empty_mask.view()), std::invalid_argument);
  Image nan = a;
  nan(4, 7) = std::numeric_limits<float>::quiet_NaN();
  try {
    mean_ssim(a.view(), nan.view());
    FAIL() << "NaN accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("b must be finite"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("(x=4, y=7)"), std::string::npos) << e.what();
  }
  SsimSettings bad;
  bad.sigma = 0;
  try {
    ssim_map(a.view(), a.view(), bad);
    FAIL() << "sigma 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "settings.sigma must be finite and > 0, got 0");
  }
}

// Hostile inputs: SSIM stays accurate and in [-1, 1] for any finite float input. E[a²] − E[a]²
// cancelled for large values: two constant images of +1e20 and −1e20 scored 1.
TEST(SsimHostile, HugeConstantsOfOppositeSignScoreMinusOne) {
  const Image a(16, 16, 1, 1e20f), b(16, 16, 1, -1e20f);
  EXPECT_NEAR(mean_ssim(a.view(), b.view()), -1.0, 1e-12);
  const Image s = ssim_map(a.view(), b.view());
  for (float v : s.pixels()) EXPECT_NEAR(v, -1.0f, 1e-6f);
  EXPECT_EQ(mean_ssim(a.view(), a.view()), 1.0);
}

TEST(SsimHostile, LargeOffsetKeepsTheStructureTerm) {
  // A constant 1e6 against 1e6 + a ±1 checkerboard: the means agree to 1e-12 and the
  // contrast term is C2 / (1 + C2), about 9e-4; the cancelling formula gave noise.
  Image a(16, 16, 1, 1e6f), b(16, 16, 1, 1e6f);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) b(x, y) += ((x + y) % 2 ? 1.0f : -1.0f);
  const double s = mean_ssim(a.view(), b.view());
  EXPECT_GT(s, 0.0);
  EXPECT_LT(s, 0.01);
}

TEST(SsimHostile, ExtremeFiniteValuesGiveFiniteSsimInRange) {
  std::mt19937 rng(7);
  const float big = std::numeric_limits<float>::max();
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int trial = 0; trial < 20; ++trial) {
    Image a(13, 12, 1), b(13, 12, 1);
    for (float& v : a.pixels()) v = big * u(rng);
    for (float& v : b.pixels()) v = (trial % 2 ? big : 1e-30f) * u(rng);
    if (trial % 3 == 0) b.pixels()[5] = big;
    const double m = mean_ssim(a.view(), b.view());
    EXPECT_TRUE(std::isfinite(m));
    EXPECT_GE(m, -1.0);
    EXPECT_LE(m, 1.0);
    const Image map = ssim_map(a.view(), b.view());
    for (float v : map.pixels()) {
      ASSERT_TRUE(std::isfinite(v));
      ASSERT_GE(v, -1.0f);
      ASSERT_LE(v, 1.0f);
    }
  }
}

TEST(SsimHostile, NonFiniteInputIsInvalidArgument) {
  Image a(12, 12, 1, 0.5f), b(12, 12, 1, 0.5f);
  b(3, 4) = std::numeric_limits<float>::infinity();
  EXPECT_THROW(ssim_map(a.view(), b.view()), std::invalid_argument);
  EXPECT_THROW(mean_ssim(a.view(), b.view()), std::invalid_argument);
}

}  // namespace
}  // namespace aolab
