// Known answers for core/scoring/metrics.h: identical images, constant offsets, masks, errors,
// thread-count independence.
#include "core/scoring/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::random_image;

TEST(Metrics, IdenticalImages) {
  const Image a = random_image(40, 30, 1);
  const Metrics m = compute_metrics(a.view(), a.view());
  EXPECT_EQ(m.mae, 0.0);
  EXPECT_EQ(m.rmse, 0.0);
  EXPECT_EQ(m.bias, 0.0);
  EXPECT_EQ(m.psnr, std::numeric_limits<double>::infinity());
  EXPECT_EQ(m.ssim, 1.0);  // exactly: every moment of a and b is computed identically
  EXPECT_EQ(m.count, 40 * 30);
}

class MetricsConstantOffset : public ::testing::TestWithParam<double> {};

TEST_P(MetricsConstantOffset, KnownAnswers) {
  const double c = GetParam();
  const Image reference = random_image(33, 21, 2, 0.3f, 0.45f);
  Image ao = reference;
  for (float& v : ao.pixels()) v = float(double(v) + c);
  const Metrics m = compute_metrics(ao.view(), reference.view());
  // ao is rounded to float, so each difference is c within ~3e-8.
  EXPECT_NEAR(m.mae, std::abs(c), 1e-6);
  EXPECT_NEAR(m.rmse, std::abs(c), 1e-6);
  EXPECT_NEAR(m.bias, c, 1e-6);
  EXPECT_NEAR(m.psnr, -20.0 * std::log10(std::abs(c)), 1e-4);
  EXPECT_EQ(m.count, 33 * 21);
  EXPECT_LT(m.ssim, 1.0);
}

INSTANTIATE_TEST_SUITE_P(Offsets, MetricsConstantOffset,
                         ::testing::Values(0.1, -0.1, 0.25, -0.25, 0.01, 0.5));

TEST(Metrics, BiasSignMeansUnderOcclusionWhenPositive) {
  // The method is brighter (less occluded) than the reference: bias > 0.
  const Image reference(8, 8, 1, 0.4f);
  const Image ao(8, 8, 1, 0.6f);
  EXPECT_GT(compute_metrics(ao.view(), reference.view()).bias, 0.0);
  EXPECT_LT(compute_metrics(reference.view(), ao.view()).bias, 0.0);
}

TEST(Metrics, MaskSelectsScoredPixels) {
  const Image reference(5, 4, 1, 0.5f);
  Image ao = reference;
  Image mask(5, 4, 1, 0.0f);
  // Two scored pixels with errors +0.125 and −0.375 (exact in float); the unscored ones are
  // wildly wrong, even NaN, and must not matter.
  ao(1, 1) = 0.625f;
  mask(1, 1) = 1.0f;
  ao(3, 2) = 0.125f;
  mask(3, 2) = 2.0f;  // any non-zero value scores
  ao(0, 0) = std::numeric_limits<float>::quiet_NaN();
  ao(4, 3) = 100.0f;
  const Metrics m = compute_metrics(ao.view(), reference.view(), mask.view());
  EXPECT_EQ(m.count, 2);
  EXPECT_DOUBLE_EQ(m.mae, 0.25);
  EXPECT_DOUBLE_EQ(m.bias, -0.125);
  EXPECT_DOUBLE_EQ(m.rmse, std::sqrt((0.125 * 0.125 + 0.375 * 0.375) / 2));
  EXPECT_DOUBLE_EQ(m.psnr, 10.0 * std::log10(2 / (0.125 * 0.125 + 0.375 * 0.375)));
  EXPECT_TRUE(std::isfinite(m.ssim));
}

TEST(Metrics, MaskedOutDifferencesLeaveIdenticalScores) {
  const Image reference = random_image(30, 30, 3);
  Image ao = reference;
  Image mask(30, 30, 1, 1.0f);
  for (int y = 0; y < 30; ++y)
    for (int x = 20; x < 30; ++x) {
      ao(x, y) = 0.0f;
      mask(x, y) = 0.0f;
    }
  const Metrics m = compute_metrics(ao.view(), reference.view(), mask.view());
  EXPECT_EQ(m.count, 20 * 30);
  EXPECT_EQ(m.mae, 0.0);
  EXPECT_EQ(m.psnr, std::numeric_limits<double>::infinity());
  EXPECT_EQ(m.ssim, 1.0);  // background is set to 1 in both before filtering
}

TEST(Metrics, RejectsMismatchedSizes) {
  const Image a(10, 8, 1, 0.5f), b(8, 10, 1, 0.5f);
  const std::string msg =
      testing::invalid_argument_message([&] { compute_metrics(a.view(), b.view()); });
  EXPECT_NE(msg.find("reference"), std::string::npos) << msg;
  EXPECT_NE(msg.find("8x10"), std::string::npos) << msg;
  const std::string mask_msg =
      testing::invalid_argument_message([&] { compute_metrics(a.view(), a.view(), b.view()); });
  EXPECT_NE(mask_msg.find("mask"), std::string::npos) << mask_msg;
}

TEST(Metrics, RejectsMultiChannelImages) {
  const Image a(6, 6, 1, 0.5f), rgb(6, 6, 3, 0.5f);
  EXPECT_NE(
      testing::invalid_argument_message([&] { compute_metrics(rgb.view(), a.view()); }).find("ao"),
      std::string::npos);
  EXPECT_NE(testing::invalid_argument_message([&] {
              compute_metrics(a.view(), rgb.view());
            }).find("reference"),
            std::string::npos);
  EXPECT_NE(testing::invalid_argument_message([&] {
              compute_metrics(a.view(), a.view(), rgb.view());
            }).find("mask"),
            std::string::npos);
}

TEST(Metrics, RejectsEmptyMask) {
  const Image a(6, 5, 1, 0.5f), mask(6, 5, 1, 0.0f);
  EXPECT_EQ(
      testing::invalid_argument_message([&] { compute_metrics(a.view(), a.view(), mask.view()); }),
      "mask must select at least one pixel, got 0");
}

TEST(Metrics, RejectsNonFiniteScoredPixel) {
  const Image reference(7, 5, 1, 0.5f);
  Image ao = reference;
  ao(3, 2) = std::numeric_limits<float>::quiet_NaN();
  ao(1, 4) = std::numeric_limits<float>::infinity();  // later in row-major order
  const std::string msg =
      testing::invalid_argument_message([&] { compute_metrics(ao.view(), reference.view()); });
  EXPECT_EQ(msg.rfind("ao ", 0), 0u) << msg;
  EXPECT_NE(msg.find("(x=3, y=2)"), std::string::npos) << msg;
  EXPECT_NE(msg.find("got nan"), std::string::npos) << msg;

  Image bad_reference = reference;
  bad_reference(6, 0) = -std::numeric_limits<float>::infinity();
  const std::string ref_msg = testing::invalid_argument_message(
      [&] { compute_metrics(reference.view(), bad_reference.view()); });
  EXPECT_EQ(ref_msg.rfind("reference ", 0), 0u) << ref_msg;
  EXPECT_NE(ref_msg.find("(x=6, y=0)"), std::string::npos) << ref_msg;
  EXPECT_NE(ref_msg.find("got -inf"), std::string::npos) << ref_msg;
}

TEST(Metrics, BitIdenticalForAnyThreadCount) {
  const Image ao = random_image(97, 61, 4);
  const Image reference = random_image(97, 61, 5);
  Image mask = random_image(97, 61, 6);
  for (float& v : mask.pixels()) v = v > 0.3f ? 1.0f : 0.0f;
  const Metrics one = compute_metrics(ao.view(), reference.view(), mask.view(), 1);
  for (int threads : {2, 3, 0}) {
    const Metrics m = compute_metrics(ao.view(), reference.view(), mask.view(), threads);
    EXPECT_EQ(m.mae, one.mae) << threads;
    EXPECT_EQ(m.rmse, one.rmse) << threads;
    EXPECT_EQ(m.psnr, one.psnr) << threads;
    EXPECT_EQ(m.bias, one.bias) << threads;
    EXPECT_EQ(m.ssim, one.ssim) << threads;
    EXPECT_EQ(m.count, one.count) << threads;
  }
}

}  // namespace
}  // namespace aolab
