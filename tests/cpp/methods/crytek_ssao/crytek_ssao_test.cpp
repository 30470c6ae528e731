// Known answers for Crytek SSAO (Mittring 2007, §8.5.4.3): the kernel (antipodal pairs, its
// distances), exactly 1/2 as published and 1 rescaled on an open plane facing the camera, the
// hemisphere variant's 1 there, the occluded fraction of the ball in a 90° crease against its
// closed form, the range check, the 4×4 tiling, very large and very small radii. What every
// method promises (background, threads, settings errors) is conformance_test's.
#include "core/methods/crytek_ssao/crytek_ssao.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <vector>

#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::SceneFixture;

CrytekSsaoSettings settings(float radius, int samples) {
  CrytekSsaoSettings s;
  s.radius = radius;
  s.samples = samples;
  return s;
}

TEST(CrytekSsaoKernel, AntipodalPairsInsideTheBall) {
  for (auto distribution : {CrytekSsaoDistribution::Centre, CrytekSsaoDistribution::Uniform}) {
    const auto k = crytek_ssao_kernel(15, distribution, 3);
    ASSERT_EQ(k.size(), 15u);
    for (std::size_t i = 0; i + 1 < k.size(); i += 2) {
      EXPECT_EQ(k[i + 1], -k[i]) << i;
      const float len = glm::length(k[i]);
      EXPECT_LE(len, 1.0f + 1e-6f);
      if (distribution == CrytekSsaoDistribution::Centre) {
        EXPECT_GE(len, kCrytekSsaoInnerScale - 1e-6f);
      }
    }
  }
  // Centre-weighted: pair k of K at lerp(0.1, 1, (k/K)²), growing outwards.
  const auto c = crytek_ssao_kernel(8, CrytekSsaoDistribution::Centre, 0);
  EXPECT_NEAR(glm::length(c[0]), 0.1f, 1e-6f);
  EXPECT_NEAR(glm::length(c[6]), 0.1f + 0.9f * 9.0f / 16.0f, 1e-6f);
  // The seed draws another kernel; the same seed the same bits.
  EXPECT_NE(crytek_ssao_kernel(8, CrytekSsaoDistribution::Uniform, 1)[0],
            crytek_ssao_kernel(8, CrytekSsaoDistribution::Uniform, 2)[0]);
  EXPECT_EQ(crytek_ssao_kernel(8, CrytekSsaoDistribution::Uniform, 1),
            crytek_ssao_kernel(8, CrytekSsaoDistribution::Uniform, 1));
}

// A plane facing the camera: every point of a pair lies on opposite sides of it, so exactly
// half the points are behind the depth buffer wherever both project into the image.
TEST(CrytekSsao, OpenPlaneIsHalfAsPublishedAndOneRescaled) {
  SceneFixture f("plane", 96, 54);
  for (int range : {0, 1, 2}) {
    CrytekSsaoSettings s = settings(0.5f, 16);
    s.range_check = range;
    s.output = int(CrytekSsaoOutput::Published);
    const Image published = crytek_ssao(f.g, s);
    s.output = int(CrytekSsaoOutput::Rescaled);
    const Image rescaled = crytek_ssao(f.g, s);
    s.hemisphere = true;
    s.output = int(CrytekSsaoOutput::Published);
    const Image hemisphere = crytek_ssao(f.g, s);
    int interior = 0;
    for (int y = 0; y < 54; ++y)
      for (int x = 0; x < 96; ++x) {
        EXPECT_EQ(rescaled(x, y), 1.0f) << x << "," << y;
        EXPECT_EQ(hemisphere(x, y), 1.0f) << x << "," << y;
        EXPECT_GE(published(x, y), 0.5f);  // points off the image do not occlude
        if (x >= 12 && x < 84 && y >= 12 && y < 42) {
          EXPECT_EQ(published(x, y), 0.5f) << x << "," << y;
          ++interior;
        }
      }
    EXPECT_GT(interior, 2000);
  }
}

// The crease's two perpendicular planes: for a point at distance h < R from the crease line,
// the solid fills half the ball plus half the cap beyond the other plane, a fraction
// f = 1/2 + (R − h)²(2R + h)/(8R³) (3/4 on the line, 1/2 from h = R on). With points
// uniform in the ball, a random reflection per pixel and no range check, the published A
// averages 1 − f (the depth buffer holds both planes, so every point inside the solid lies
// behind it along its view ray).
TEST(CrytekSsao, CreaseMatchesTheBallFraction) {
  const float radius = 0.5f;  // about 14 px on screen: every point of the pixels below projects
                              // into the image
  SceneFixture f("crease", 160, 90);
  CrytekSsaoSettings s = settings(radius, 256);
  s.distribution = int(CrytekSsaoDistribution::Uniform);
  s.rotation = int(CrytekSsaoRotation::PerPixel);
  s.range_check = int(CrytekSsaoRangeCheck::Off);
  s.output = int(CrytekSsaoOutput::Published);
  const Image ao = crytek_ssao(f.g, s);
  const double d = 5.0, r = radius;
  double sum_err = 0, sum_abs = 0;
  int n = 0;
  for (int y = 20; y < 70; ++y)
    for (int x = 20; x < 140; ++x) {
      const glm::vec3 p =
          f.g.camera.view_position(float(x) + 0.5f, float(y) + 0.5f, f.g.depth(x, y));
      const double h = std::hypot(double(p.y), double(p.z) + d);
      const double frac = h < r ? 0.5 + (r - h) * (r - h) * (2 * r + h) / (8 * r * r * r) : 0.5;
      const double err = double(ao(x, y)) - (1.0 - frac);
      sum_err += err;
      sum_abs += std::abs(err);
      ++n;
    }
  ASSERT_GT(n, 3000);
  EXPECT_LT(std::abs(sum_err / n), 0.01) << "mean signed error";
  EXPECT_LT(sum_abs / n, 0.03) << "mean |error| (256 points: sampling noise ~0.02)";
}

// The range check discounts occluders far in front of a point: a plane 3R in front of a
// floor hides nothing with the check on (smooth or hard), everything behind it without.
TEST(CrytekSsao, RangeCheckIgnoresDistantOccluders) {
  SceneFixture f("plane", 64, 36);
  // Depth 5 everywhere but a nearer square at depth 5 − 3R in the middle.
  const float radius = 0.5f;
  for (int y = 12; y < 24; ++y)
    for (int x = 24; x < 40; ++x) f.scene.depth(x, y) = 5.0f - 3.0f * radius;
  CrytekSsaoSettings s = settings(radius, 16);
  s.hemisphere = true;
  s.output = int(CrytekSsaoOutput::Published);
  // A pixel of the far plane beside the square: its points reach under the square.
  const int x = 22, y = 18;
  s.range_check = int(CrytekSsaoRangeCheck::Off);
  const float off = crytek_ssao(f.g, s)(x, y);
  s.range_check = int(CrytekSsaoRangeCheck::Smooth);
  const float smooth = crytek_ssao(f.g, s)(x, y);
  s.range_check = int(CrytekSsaoRangeCheck::Hard);
  const float hard = crytek_ssao(f.g, s)(x, y);
  EXPECT_LT(off, 1.0f);
  EXPECT_EQ(smooth, 1.0f);
  EXPECT_EQ(hard, 1.0f);
}

// The course's 4×4 texture. The crease's depth is the same along each row and its geometry
// is the same along x, so two pixels of a row sharing a reflection vector (4 apart) give the
// same bits; with a vector per pixel they differ.
TEST(CrytekSsao, TiledRotationRepeatsEveryFourPixels) {
  SceneFixture f("crease", 160, 90);
  CrytekSsaoSettings s = settings(1.0f, 8);
  s.output = int(CrytekSsaoOutput::Published);
  const Image tiled = crytek_ssao(f.g, s);
  s.rotation = int(CrytekSsaoRotation::PerPixel);
  const Image per_pixel = crytek_ssao(f.g, s);
  int differ = 0;
  for (int y = 30; y < 60; ++y)
    for (int x = 60; x < 96; ++x) {
      EXPECT_EQ(tiled(x, y), tiled(x + 4, y)) << x << "," << y;
      differ += per_pixel(x, y) != per_pixel(x + 4, y);
    }
  EXPECT_GT(differ, 100);
}

// Extreme radii stay finite: beyond the scene every point leaves the image or the camera's
// front (A as far as the visible points say), below a pixel every point reads its own
// pixel's depth, on the plane (1).
TEST(CrytekSsao, ExtremeRadiiAreFinite) {
  SceneFixture f("blocks", 96, 54);
  for (float radius : {1e-12f, 1e-6f, 1e6f, 1e19f, 1e30f}) {
    const Image ao = crytek_ssao(f.g, settings(radius, 16));
    for (float v : ao.pixels()) {
      ASSERT_TRUE(std::isfinite(v)) << radius;
      ASSERT_GE(v, 0.0f);
      ASSERT_LE(v, 1.0f);
    }
  }
  const Image tiny = crytek_ssao(f.g, settings(1e-12f, 16));
  for (float v : tiny.pixels()) EXPECT_EQ(v, 1.0f);
}

}  // namespace
}  // namespace aolab
