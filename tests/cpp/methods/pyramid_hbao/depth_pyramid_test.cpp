// The depth pyramid of Pyramid HBAO (§3.3): sizes, means, background, centroids, and the
// property that keeps averaged planes from occluding themselves.
#include "core/methods/pyramid_hbao/depth_pyramid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>
#include <vector>

#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::SceneFixture;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

int ceil_div_power(int size, int k, int l) {
  double s = size;
  for (int i = 0; i < l; ++i) s = std::ceil(s / k);
  return int(s);
}

struct Shape {
  int w, h, k;
};

class DepthPyramidShapes : public ::testing::TestWithParam<Shape> {};

// A constant depth stays exactly constant at every level (means are rounded once, from
// double), and level l is ⌈w/K^l⌉ × ⌈h/K^l⌉, down to 1×1.
TEST_P(DepthPyramidShapes, ConstantDepthIsConstantAtEveryLevel) {
  const Shape s = GetParam();
  for (float depth : {0.1f, 3.0f, 7.3e4f}) {
    const DepthPyramid p(std::vector<float>(std::size_t(s.w) * s.h, depth), s.w, s.h, s.k);
    ASSERT_EQ(p.levels(), DepthPyramid::full_levels(s.w, s.h, s.k));
    for (int l = 0; l < p.levels(); ++l) {
      const DepthPyramidLevel& level = p.level(l);
      EXPECT_EQ(level.width, ceil_div_power(s.w, s.k, l)) << "level " << l;
      EXPECT_EQ(level.height, ceil_div_power(s.h, s.k, l)) << "level " << l;
      EXPECT_EQ(level.scale, int(std::lround(std::pow(s.k, l))));
      for (const PyramidTexel& t : level.texels) ASSERT_EQ(t.depth, depth) << "level " << l;
    }
    const DepthPyramidLevel& top = p.level(p.levels() - 1);
    EXPECT_EQ(top.width * top.height, 1);
  }
}

INSTANTIATE_TEST_SUITE_P(Sizes, DepthPyramidShapes,
                         ::testing::Values(Shape{1, 1, 3}, Shape{1, 7, 3}, Shape{300, 1, 2},
                                           Shape{2, 2, 3}, Shape{160, 90, 3}, Shape{160, 90, 2},
                                           Shape{97, 61, 4}, Shape{81, 27, 3}));

TEST(DepthPyramid, FullLevelsCountsDownToOneTexel) {
  EXPECT_EQ(DepthPyramid::full_levels(1, 1, 3), 1);
  EXPECT_EQ(DepthPyramid::full_levels(3, 1, 3), 2);
  EXPECT_EQ(DepthPyramid::full_levels(4, 1, 3), 3);
  EXPECT_EQ(DepthPyramid::full_levels(160, 90, 3), 6);  // 160, 54, 18, 6, 2, 1
  EXPECT_EQ(DepthPyramid::full_levels(1280, 720, 2), 12);
}

TEST(DepthPyramid, LevelsArguments) {
  const std::vector<float> depth(160 * 90, 2.0f);
  EXPECT_EQ(DepthPyramid(depth, 160, 90, 3, 2).levels(), 2);
  EXPECT_EQ(DepthPyramid(depth, 160, 90, 3, 1).levels(), 1);
  EXPECT_EQ(DepthPyramid(depth, 160, 90, 3, 100).levels(), 6);  // capped at 1×1
  using testing::invalid_argument_message;
  EXPECT_NE(invalid_argument_message([&] { DepthPyramid(depth, 160, 90, 1); }).find("reduction"),
            std::string::npos);
  EXPECT_NE(invalid_argument_message([&] { DepthPyramid(depth, 160, 90, 3, -1); }).find("levels"),
            std::string::npos);
  EXPECT_NE(invalid_argument_message([&] { DepthPyramid(depth, 16, 90, 3); }).find("depth"),
            std::string::npos);
}

// §3.3: a texel is the mean of its K×K children. Background never enters it, and a texel
// with no geometry below it is background.
TEST(DepthPyramid, MeansSkipBackground) {
  // 4×3 with K = 3: level 1 is 2×1; texel (0, 0) covers columns 0–2, texel (1, 0) column 3.
  const std::vector<float> depth = {1.0f, 2.0f, kNaN,  5.0f,   //
                                    4.0f, 0.0f, 6.0f,  -1.0f,  //
                                    7.0f, 8.0f, 1e10f, kNaN};
  const DepthPyramid p(depth, 4, 3, 3);
  ASSERT_EQ(p.levels(), 3);
  // 0 and −1 are background; 1e10 is geometry for the raw-depth constructor (no threshold).
  const PyramidTexel a = p.level(1)(0, 0), b = p.level(1)(1, 0);
  EXPECT_FLOAT_EQ(a.depth, float((1.0 + 2 + 4 + 6 + 7 + 8 + 1e10) / 7));
  EXPECT_FLOAT_EQ(a.x, float((0.5 + 1.5 + 0.5 + 2.5 + 0.5 + 1.5 + 2.5) / 7));
  EXPECT_FLOAT_EQ(a.y, float((0.5 + 0.5 + 1.5 + 1.5 + 2.5 + 2.5 + 2.5) / 7));
  EXPECT_EQ(b.depth, 5.0f);  // only (3, 0) holds geometry
  EXPECT_EQ(b.x, 3.5f);
  EXPECT_EQ(b.y, 0.5f);

  // Through a G-buffer, its background rule applies (1e10 is background by default).
  Image img(4, 3, 1);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) img(x, y) = depth[std::size_t(y) * 4 + x];
  GBuffer g;
  g.depth = img.view();
  g.camera = {4, 4, 2, 1.5f};
  const DepthPyramid pg(g, 3);
  EXPECT_FLOAT_EQ(pg.level(1)(0, 0).depth, float((1.0 + 2 + 4 + 6 + 7 + 8) / 6));

  // All background: the texel is background at every level above.
  const DepthPyramid empty(std::vector<float>(9, kNaN), 3, 3, 3);
  EXPECT_TRUE(std::isnan(empty.level(1)(0, 0).depth));
}

// Whole footprints have their centre as centroid, K^l (X + ½); footprints cut by the image
// border have the centre of the pixels inside.
TEST(DepthPyramid, CentroidsAreFootprintCentres) {
  std::vector<float> depth(10 * 7);
  for (std::size_t i = 0; i < depth.size(); ++i) depth[i] = 1.0f + 0.01f * float(i);
  const DepthPyramid p(depth, 10, 7, 3);
  const PyramidTexel& whole = p.level(1)(1, 1);
  EXPECT_EQ(whole.x, 4.5f);
  EXPECT_EQ(whole.y, 4.5f);
  const PyramidTexel& cut = p.level(1)(3, 2);  // column 9 and row 6 only
  EXPECT_EQ(cut.x, 9.5f);
  EXPECT_EQ(cut.y, 6.5f);
  EXPECT_EQ(cut.depth, depth[6 * 10 + 9]);
  // Level 2 texel (0, 0) averages level-1 texels (0..2, 0..2): the plain mean of their
  // centroids, with the weights of the depth mean (each child counts once).
  const PyramidTexel& two = p.level(2)(0, 0);
  EXPECT_FLOAT_EQ(two.x, 4.5f);
  EXPECT_FLOAT_EQ(two.y, float((1.5 + 4.5 + 6.5) / 3));  // level-1 rows 0, 1 and the cut row 2
}

// Planar depth is a convex function of the pixel position (1/d is affine on a plane), so
// the mean depth of a texel is never nearer than the plane on the ray through the texel's
// centroid (Jensen). This is why averaging cannot make a plane occlude itself; the bound
// allows the float rounding of the stored depths and means (one unit of 2^-24 per level,
// plus the plane's own).
TEST(DepthPyramid, AveragedPlaneLiesOnOrBehindThePlane) {
  struct Case {
    double tilt, azimuth, fov;
  };
  for (const Case c : {Case{0, 0, 60}, Case{30, 45, 60}, Case{60, 0, 90}, Case{85, 30, 60},
                       Case{-85, 200, 120}, Case{89, 90, 30}})
    for (int k : {2, 3}) {
      SceneFixture f("plane", 160, 90, {{"tilt", c.tilt}, {"azimuth", c.azimuth}, {"fov", c.fov}});
      const double t = c.tilt * std::numbers::pi / 180, a = c.azimuth * std::numbers::pi / 180;
      const glm::dvec3 n(std::sin(t) * std::sin(a), std::sin(t) * std::cos(a), std::cos(t));
      const double offset = -5.0 * n.z;  // the plane n·X = offset passes through (0, 0, −5)
      const DepthPyramid p(f.g, k);
      // The renderer's rays, in double: the float intrinsics would move a grazing plane's
      // depth by far more than its rounding.
      const double focal = 80.0 / std::tan(c.fov * std::numbers::pi / 360), cx = 80, cy = 45;
      int checked = 0;
      for (int l = 1; l < p.levels(); ++l)
        for (const PyramidTexel& texel : p.level(l).texels) {
          if (std::isnan(texel.depth)) continue;
          const glm::dvec3 ray((texel.x - cx) / focal, -(texel.y - cy) / focal, -1.0);
          const double plane_depth = offset / glm::dot(n, ray);
          ASSERT_GE(double(texel.depth), plane_depth * (1.0 - (l + 2) * 0x1p-24))
              << "tilt " << c.tilt << " K " << k << " level " << l;
          ++checked;
        }
      EXPECT_GT(checked, 100);
    }
}

TEST(DepthPyramid, BitIdenticalAcrossThreadCounts) {
  SceneFixture f("blocks", 200, 120);
  const DepthPyramid a(f.g, 3, 0, 1), b(f.g, 3, 0, 2), c(f.g, 3, 0, 7);
  for (int l = 0; l < a.levels(); ++l)
    for (std::size_t i = 0; i < a.level(l).texels.size(); ++i) {
      const PyramidTexel &ta = a.level(l).texels[i], &tb = b.level(l).texels[i],
                         &tc = c.level(l).texels[i];
      ASSERT_EQ(std::memcmp(&ta, &tb, sizeof ta), 0);
      ASSERT_EQ(std::memcmp(&ta, &tc, sizeof ta), 0);
    }
}

}  // namespace
}  // namespace aolab
