// VAO (Szirmay-Kalos et al. 2010 as outlined in VAO++ §3; core/methods/vao/vao.h): eq. 2 against
// its closed form, the three pipe cases of Figure 3 on a synthetic configuration, creases.
// What every method promises (planes, background, threads, settings errors) is
// conformance_test's.
#include "core/methods/vao/vao.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/cpp/methods/vao/convex_room.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::SceneFixture;

TEST(VaoEq2, TendsToTheClosedFormOfEq1) {
  // Eq. 1: F = |S| / (R²π/(4n)) = (4π(R/2)³/3) / (R²π/(4n)) = 2Rn/3 for uniform samples;
  // eq. 2 estimates it with the samples themselves.
  for (double radius : {0.5, 1.0, 7.0}) {
    for (int n : {16, 256, 4096}) {
      const double f = vao_eq2_normaliser(vao_spiral_kernel(n), radius);
      const double closed = 2.0 * radius * n / 3.0;
      EXPECT_NEAR(f / closed, 1.0, n >= 4096 ? 1e-4 : n >= 256 ? 2e-3 : 2e-2) << n;
    }
  }
  // One sample at the centre: a pipe of length R (the sphere's diameter).
  EXPECT_DOUBLE_EQ(vao_eq2_normaliser(vao_kernel({{0.0f, 0.0f}}), 3.0), 3.0);
  // On the rim: no pipe.
  EXPECT_DOUBLE_EQ(vao_eq2_normaliser(vao_kernel({{1.0f, 0.0f}}), 3.0), 0.0);
}

TEST(VaoPipes, TheThreeCasesOfFigure3) {
  const VaoPipe pipe{2.0f, 3.0f};
  EXPECT_EQ(vao_case(pipe, 3.5f, 0.0f), VaoCase::B);
  EXPECT_EQ(vao_case(pipe, NAN, 0.0f), VaoCase::B);  // background never occludes
  EXPECT_EQ(vao_case(pipe, 2.25f, 0.0f), VaoCase::A);
  EXPECT_EQ(vao_case(pipe, 1.5f, 0.0f), VaoCase::C);
  EXPECT_EQ(vao_case(pipe, 2.999f, 0.01f), VaoCase::B);  // within the rounding tolerance
  EXPECT_FLOAT_EQ(vao_unoccluded_length(pipe, 3.5f, 0.0f, false, 1.0f), 1.0f);
  EXPECT_FLOAT_EQ(vao_unoccluded_length(pipe, 2.25f, 0.0f, false, 1.0f), 0.25f);
  EXPECT_FLOAT_EQ(vao_unoccluded_length(pipe, 1.5f, 0.0f, false, 1.0f), 0.0f);
  // Range check (VAO++ eq. 4): the sample point (2.5) lies 1 behind the surface at 1.5:
  // s = 0.03 / max(0.03, 1/1) = 0.03 of the occlusion remains.
  EXPECT_FLOAT_EQ(vao_unoccluded_length(pipe, 1.5f, 0.0f, true, 1.0f), 0.97f);
  EXPECT_FLOAT_EQ(vao_unoccluded_length(pipe, 1.5f, 0.0f, true, 100.0f), 0.0f);  // d <= uR
  EXPECT_FLOAT_EQ(vao_unoccluded_length(pipe, 2.6f, 0.0f, true, 1.0f), 0.6f);    // in front: s = 1
  EXPECT_FLOAT_EQ(vao_range_falloff(0.0f, 2.0f), 1.0f);
  EXPECT_FLOAT_EQ(vao_range_falloff(0.06f, 2.0f), 1.0f);
  EXPECT_FLOAT_EQ(vao_range_falloff(0.6f, 2.0f), 0.1f);
}

// A 101×101 plane facing the camera at depth 5, P at the centre pixel on the view axis,
// R = 1: the tangent sphere has centre depth 4.5, radius 0.5. One sample at disc point
// (0.6, 0): S = (0.3, 0, -4.5) projects to x = 50.5 + 100·0.3/4.5 = 57.17 (texel 57).
struct OneSample {
  Image depth{101, 101, 1, 5.0f}, normal{101, 101, 3, 0.0f};
  GBuffer g;
  OneSample(float occluder_depth) {
    for (int y = 0; y < 101; ++y)
      for (int x = 0; x < 101; ++x) normal(x, y, 2) = 1.0f;
    depth(57, 50) = occluder_depth;
    g.depth = depth.view();
    g.normal = normal.view();
    g.camera = {100.0f, 100.0f, 50.5f, 50.5f};
  }
  float ao(bool view_ray_pipes) const {
    const VaoFrame f = vao_frame(g, false, 1);
    VaoPixelOptions o;
    o.radius = 1.0f;
    o.view_ray_pipes = view_ray_pipes;
    const float x = 0.6f, y = 0.0f, h = 0.8f;
    return vao_pixel(f, o, 50, 50, &x, &y, &h, 1).ao();
  }
};

TEST(VaoPipes, ParallelPipeCasesOnASyntheticConfiguration) {
  // Pipe parallel to the view axis: depths 4.5 ± 0.5·0.8 = [4.1, 4.9].
  EXPECT_EQ(OneSample(5.0f).ao(false), 1.0f);                 // B: the plane lies behind
  EXPECT_NEAR(OneSample(4.5f).ao(false), 0.4f / 0.8f, 1e-6);  // A: half the pipe is open
  EXPECT_NEAR(OneSample(4.3f).ao(false), 0.2f / 0.8f, 1e-6);  // A
  EXPECT_EQ(OneSample(4.0f).ao(false), 0.0f);                 // C: occluded in front
}

TEST(VaoPipes, ViewRayPipeCasesOnASyntheticConfiguration) {
  // The pipe runs along the ray through texel 57's centre, v = (0.07, 0, -1): it meets the
  // sphere |δv - C| = 0.5, C = (0, 0, -4.5), at δ = (4.5 ± sqrt(4.5² - |v|²(4.5² - 0.25)))/|v|².
  const double a = 1.0 + 0.07 * 0.07, b = 4.5, c = 4.5 * 4.5 - 0.25;
  const double front = (b - std::sqrt(b * b - a * c)) / a,
               back = (b + std::sqrt(b * b - a * c)) / a;
  EXPECT_EQ(OneSample(5.0f).ao(true), 1.0f);
  const float mid = float(0.5 * (front + back));
  EXPECT_NEAR(OneSample(mid).ao(true), 0.5, 1e-5);
  const float quarter = float(front + 0.25 * (back - front));
  EXPECT_NEAR(OneSample(quarter).ao(true), 0.25, 1e-5);
  EXPECT_EQ(OneSample(float(front) - 0.01f).ao(true), 0.0f);
}

TEST(Vao, OccludesCreases) {
  VaoSettings s;
  s.radius = 1.0f;
  SceneFixture crease("crease", 160, 90);
  EXPECT_LT(testing::min_valid(vao(crease.g, s), crease.g), 0.6f);
}

// Beyond the scene's extent a larger R cannot change the occlusion: the tangent sphere is then
// the half-space in front of the tangent plane at any R. R = 1e6 times the scene's depth and
// R up to the accepted maximum 1e30 must agree (float arithmetic on the sphere overflowed b² at
// R ~ 1e19 and drifted to 1: 0.90 at 1e19, 0.99 at 1e20, 1 at 1e22).
TEST(Vao, LargeRadiiBeyondTheSceneGiveTheSameAo) {
  testing::ConvexRoom room;
  for (bool view_ray_pipes : {true, false}) {
    VaoSettings s;
    s.view_ray_pipes = view_ray_pipes;
    testing::expect_large_radii_agree(
        room,
        [&](float radius) {
          s.radius = radius;
          return vao(room.g, s);
        },
        0.95, "view_ray_pipes = " + std::to_string(view_ray_pipes));
  }
}

}  // namespace
}  // namespace aolab
