#include "core/base/gbuffer.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <glm/geometric.hpp>
#include <limits>
#include <utility>

#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

TEST(Background, Rule) {
  const float t = kDefaultBackgroundDepth;
  EXPECT_TRUE(is_geometry(1e-3f, t));
  EXPECT_TRUE(is_geometry(1e5f, t));
  EXPECT_TRUE(is_geometry(65504.0f, t));  // EEVEE's background is geometry unless told
  EXPECT_FALSE(is_geometry(65504.0f, 65504.0f));
  EXPECT_FALSE(is_geometry(1e10f, t));  // Cycles' background
  EXPECT_FALSE(is_geometry(0.0f, t));
  EXPECT_FALSE(is_geometry(-1.0f, t));
  EXPECT_FALSE(is_geometry(std::numeric_limits<float>::infinity(), t));
  EXPECT_FALSE(is_geometry(std::numeric_limits<float>::quiet_NaN(), t));
}

TEST(Camera, ReconstructionAndProjectionAreInverse) {
  const CameraIntrinsics c{800.0f, 780.0f, 321.5f, 170.25f};
  for (float px : {0.5f, 100.5f, 639.5f})
    for (float py : {0.5f, 359.5f})
      for (float d : {0.01f, 5.0f, 1e4f}) {
        const glm::vec3 p = c.view_position(px, py, d);
        EXPECT_FLOAT_EQ(p.z, -d);
        const glm::vec3 q = c.project(p);
        EXPECT_NEAR(q.x, px, 1e-3f * std::max(1.0f, px));
        EXPECT_NEAR(q.y, py, 1e-3f * std::max(1.0f, py));
        EXPECT_FLOAT_EQ(q.z, d);
      }
  // Centre of projection maps to the optical axis; right of it is +x, below it is -y.
  const glm::vec3 axis = c.view_position(c.cx, c.cy, 2.0f);
  EXPECT_EQ(axis.x, 0.0f);
  EXPECT_EQ(axis.y, 0.0f);
  EXPECT_GT(c.view_position(c.cx + 10, c.cy + 10, 2.0f).x, 0.0f);
  EXPECT_LT(c.view_position(c.cx + 10, c.cy + 10, 2.0f).y, 0.0f);
}

TEST(Camera, ValidateNamesParameter) {
  for (auto [c, name] : {std::pair{CameraIntrinsics{0, 1, 0, 0}, "fx"},
                         std::pair{CameraIntrinsics{1, -1, 0, 0}, "fy"},
                         std::pair{CameraIntrinsics{1, 1, NAN, 0}, "cx"},
                         std::pair{CameraIntrinsics{1, 1, 0, INFINITY}, "cy"}}) {
    try {
      c.validate();
      FAIL() << name;
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind(name, 0), 0u) << e.what();
    }
  }
}

TEST(GBuffer, ValidateShapes) {
  Image depth(4, 3, 1, 1.0f), normal(4, 3, 3, 0.0f), wrong(3, 3, 3, 0.0f);
  GBuffer g;
  g.depth = depth.view();
  g.camera = {10, 10, 2, 1.5f};
  EXPECT_NO_THROW(g.validate());
  g.normal = wrong.view();
  EXPECT_THROW(g.validate(), std::invalid_argument);
  g.normal = normal.view();
  EXPECT_NO_THROW(g.validate());
  g.background_depth = 0;
  EXPECT_THROW(g.validate(), std::invalid_argument);
}

TEST(PreparedNormals, RenormalisesFlipsAndReplaces) {
  // A plane facing the camera at depth 2, 5x5, with hand-made normal defects.
  Image depth(5, 5, 1, 2.0f), normal(5, 5, 3, 0.0f);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x) normal(x, y, 2) = 1.0f;
  normal(1, 1, 2) = 0.5f;                                     // non-unit
  normal(2, 2, 2) = -1.0f;                                    // facing away
  normal(3, 3, 2) = 0.0f;                                     // zero
  normal(4, 4, 0) = std::numeric_limits<float>::quiet_NaN();  // NaN
  depth(0, 4) = 1e10f;                                        // background
  GBuffer g;
  g.depth = depth.view();
  g.normal = normal.view();
  g.camera = {5, 5, 2.5f, 2.5f};
  const Image n = prepared_normals(g);
  for (auto [x, y] : {std::pair{1, 1}, {2, 2}, {3, 3}, {4, 4}, {0, 0}}) {
    EXPECT_NEAR(n(x, y, 0), 0.0f, 1e-6f) << x << "," << y;
    EXPECT_NEAR(n(x, y, 1), 0.0f, 1e-6f) << x << "," << y;
    EXPECT_NEAR(n(x, y, 2), 1.0f, 1e-6f) << x << "," << y;
  }
  EXPECT_EQ(n(0, 4, 2), 0.0f);  // background stays zero
}

TEST(PreparedNormals, FromDepthMatchesAnalyticNormals) {
  testing::SceneFixture f("blocks", 160, 90);
  GBuffer no_normals = f.g;
  no_normals.normal = {};
  const Image est = prepared_normals(no_normals);
  int agree = 0, total = 0;
  for (int y = 0; y < 90; ++y)
    for (int x = 0; x < 160; ++x) {
      if (!f.g.valid(x, y)) continue;
      ++total;
      const glm::vec3 a(est(x, y, 0), est(x, y, 1), est(x, y, 2));
      const glm::vec3 b(f.scene.normal(x, y, 0), f.scene.normal(x, y, 1), f.scene.normal(x, y, 2));
      if (glm::dot(a, b) > 0.999f) ++agree;
    }
  // Flat faces agree; only pixels on creases (both neighbours across an edge) may not.
  EXPECT_GT(double(agree) / total, 0.97);
}

// prepared_normals runs the usual pixel in SIMD (gbuffer_simd.cpp): bit for bit the scalar
// rule of prepared_normal, on a scene whose normals hold every defect, at a width that is no
// multiple of any vector length, with a strided view.
TEST(PreparedNormals, SimdRowsAreBitForBitTheRule) {
  testing::SceneFixture f("blocks", 203, 37);
  Image normal(203, 37, 3);
  const Image noise = testing::random_image(203, 37, 11, -0.2f, 0.2f);
  for (int y = 0; y < 37; ++y)
    for (int x = 0; x < 203; ++x)
      for (int c = 0; c < 3; ++c) normal(x, y, c) = f.g.normal(x, y, c) * 0.97f + noise(x, y);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int x = 0; x < 203; x += 7) {
    normal(x, 3, 0) = nan;                                           // NaN
    normal(x, 5, 0) = normal(x, 5, 1) = normal(x, 5, 2) = 0.0f;      // zero
    for (int c = 0; c < 3; ++c) normal(x, 9, c) = -normal(x, 9, c);  // facing away
    normal(x, 11, 2) = std::numeric_limits<float>::infinity();       // infinite
  }
  Image depth(203, 37, 1);
  for (int y = 0; y < 37; ++y)
    for (int x = 0; x < 203; ++x) depth(x, y) = f.g.depth(x, y);
  for (int x = 0; x < 203; x += 5) depth(x, 17) = x % 2 ? nan : -1.0f;  // background
  GBuffer g = f.g;
  g.depth = std::as_const(depth).view();
  g.normal = std::as_const(normal).view();
  for (int threads : {1, 2}) {
    const Image n = prepared_normals(g, threads);
    for (int y = 0; y < 37; ++y)
      for (int x = 0; x < 203; ++x) {
        const glm::vec3 p = prepared_normal(g, x, y);
        for (int c = 0; c < 3; ++c)
          ASSERT_EQ(std::bit_cast<std::uint32_t>(n(x, y, c)), std::bit_cast<std::uint32_t>(p[c]))
              << x << "," << y << "," << c;
      }
  }
}

TEST(PreparedNormals, OnePixelImage) {
  Image depth(1, 1, 1, 3.0f);
  GBuffer g;
  g.depth = depth.view();
  g.camera = {1, 1, 0.5f, 0.5f};
  const Image n = prepared_normals(g);
  EXPECT_FLOAT_EQ(n(0, 0, 2), 1.0f);  // towards the camera
}

// Hostile inputs: an empty depth names its height and width, in that order.
TEST(GBufferValidate, EmptyDepthSaysHeightAndWidth) {
  Image depth(5, 0, 1);
  GBuffer g;
  g.depth = depth.view();
  g.depth.width = 5;
  g.depth.height = 0;
  g.camera = CameraIntrinsics{1, 1, 0, 0};
  const std::string msg = testing::invalid_argument_message([&] { g.validate(); });
  EXPECT_NE(msg.find("height 0, width 5"), std::string::npos) << msg;
}

}  // namespace
}  // namespace aolab
