// Known answers for the screen-space limit: where the depth buffer holds every occluder the
// limit is the reference's own integral, so it meets the closed forms of the analytic scenes
// within its Monte-Carlo error; thickness, rays leaving the image and the seed do what
// docs/methods/screen_space_limit.md says. What every method promises (planes, background,
// threads, settings errors) is conformance_test's.
#include "core/methods/screen_space_limit/screen_space_limit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/scenes/analytic_scenes.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::invalid_argument_message;
using testing::mean_value;
using testing::min_valid;
using testing::SceneFixture;

// Whether every ray of length R from pixel (x, y) stays inside the image and in front of the
// camera: the cube of half-side R around the pixel's point contains the sphere, and a convex
// set in front of the camera projects inside the hull of its corners' projections.
bool sphere_in_view(const GBuffer& g, int x, int y, double radius) {
  const float d = g.depth(x, y);
  const glm::vec3 p = g.camera.view_position(float(x) + 0.5f, float(y) + 0.5f, d);
  for (int corner = 0; corner < 8; ++corner) {
    const glm::vec3 c = p + float(radius) * glm::vec3(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1,
                                                      corner & 4 ? 1 : -1);
    if (!(c.z < -1e-3f)) return false;
    const glm::vec3 q = g.camera.project(c);
    if (!(q.x >= 0 && q.x <= float(g.width()) && q.y >= 0 && q.y <= float(g.height())))
      return false;
  }
  return true;
}

// Rows [top, top + rows) of an analytic scene, with the principal point moved to match: the
// same view of the same scene through a smaller window.
struct Crop {
  Image depth, normal, reference;
  GBuffer g;
  Crop(const AnalyticGBuffer& scene, int top, int rows)
      : depth(scene.depth.width(), rows, 1),
        normal(scene.depth.width(), rows, 3),
        reference(scene.depth.width(), rows, 1) {
    for (int y = 0; y < rows; ++y)
      for (int x = 0; x < depth.width(); ++x) {
        depth(x, y) = scene.depth(x, y + top);
        reference(x, y) = scene.reference(x, y + top);
        for (int c = 0; c < 3; ++c) normal(x, y, c) = scene.normal(x, y + top, c);
      }
    g.depth = depth.view();
    g.normal = normal.view();
    g.camera = scene.camera;
    g.camera.cy -= float(top);
  }
};

struct Agreement {
  double mean_ao = 0, mean_reference = 0, sigma = 0;  // sigma: binomial std of mean_ao
  int pixels = 0;
};

// The limit against the scene's closed-form reference, averaged over the pixels whose rays
// all stay in view. Binomial bound on the noise: each pixel's estimate has variance at most
// p(1 − p)/N (stratification only lowers it), so the mean of M independent pixels has
// standard deviation at most √(Σ p(1 − p)/N)/M.
Agreement agreement(const GBuffer& g, const Image& reference, const ScreenSpaceLimitSettings& s) {
  const Image ao = screen_space_limit(g, s);
  Agreement a;
  double variance = 0;
  for (int y = 0; y < ao.height(); ++y)
    for (int x = 0; x < ao.width(); ++x) {
      const float ref = reference(x, y);
      if (!g.valid(x, y) || std::isnan(ref) || !sphere_in_view(g, x, y, s.radius)) continue;
      a.mean_ao += ao(x, y), a.mean_reference += ref;
      variance += ref * (1.0 - ref) / s.rays;
      ++a.pixels;
    }
  a.mean_ao /= a.pixels, a.mean_reference /= a.pixels;
  a.sigma = std::sqrt(variance) / a.pixels;
  return a;
}

// Tolerance of every closed-form test: 4 binomial standard deviations of the mean (a false
// failure about once in 16 000 runs, and the seeds are fixed) plus 2e-3 for what the
// depth-buffer reconstruction itself changes at the crease pixels, which straddle two
// planes but carry one.
constexpr double kSigmas = 4.0, kReconstruction = 2e-3;

ScreenSpaceLimitSettings settings(float radius, float thickness, int rays = 64) {
  ScreenSpaceLimitSettings s;
  s.radius = radius;
  s.thickness = thickness;
  s.rays = rays;
  return s;
}

// The ceiling scene shows both planes: the ceiling fills the top half of the image, the
// floor the bottom half, and a point projecting into either half in front of its surface is
// between the planes. So a ray from the floor is behind a visible pixel exactly when it has
// passed the ceiling: with unbounded thickness the limit is the reference's integral. A
// thickness of a fraction of R works too: the ray crosses the ceiling inside the image, and
// the pixel where it does sees a gap of 0. Only the 40 rows about the horizon are kept (the
// scored pixels' rays stay inside them), which keeps the test fast.
TEST(ScreenSpaceLimit, CeilingMatchesClosedForm) {
  const SceneFixture f("ceiling", 256, 144, {{"radius", 2.0}});
  const Crop crop(f.scene, 52, 40);
  const double expected = cycles_ao_under_ceiling(1.0, 2.0);  // (h/R)² = 0.25
  for (float thickness : {kScreenSpaceLimitUnbounded, 0.5f}) {
    const Agreement a = agreement(crop.g, crop.reference, settings(2.0f, thickness));
    ASSERT_GT(a.pixels, 1000);
    EXPECT_NEAR(a.mean_reference, expected, 1e-6);
    EXPECT_NEAR(a.mean_ao, expected, kSigmas * a.sigma + kReconstruction)
        << "thickness " << thickness << " over " << a.pixels << " pixels";
  }
}

// Wall and crease: both planes face the camera and are visible wherever a ray could meet
// them, so the same argument holds: cycles_ao_beside_wall on every pixel whose rays stay in
// view, for unbounded thickness and for a thickness of R/4.
TEST(ScreenSpaceLimit, WallAndCreaseMatchClosedForm) {
  for (const char* scene : {"wall", "crease"})
    for (float thickness : {kScreenSpaceLimitUnbounded, 0.125f}) {
      const SceneFixture f(scene, 192, 108, {{"radius", 0.5}});
      const Agreement a = agreement(f.g, f.scene.reference, settings(0.5f, thickness));
      ASSERT_GT(a.pixels, 1000) << scene;
      EXPECT_LT(a.mean_reference, 0.95) << scene;  // the test sees occlusion
      EXPECT_NEAR(a.mean_ao, a.mean_reference, kSigmas * a.sigma + kReconstruction)
          << scene << " thickness " << thickness << " over " << a.pixels << " pixels";
    }
}

// Per pixel, too: on the crease line the second plane hides half of the hemisphere, and with
// N = 1024 rays a pixel's standard error is at most √(0.25/1024) = 0.016.
TEST(ScreenSpaceLimit, CreaseLineIsOneHalfPerPixel) {
  const SceneFixture f("crease", 96, 54, {{"radius", 1.0}});
  const Image ao = screen_space_limit(f.g, settings(1.0f, kScreenSpaceLimitUnbounded, 1024));
  for (int x = 30; x < 66; ++x) {
    const float ref = f.scene.reference(x, 26);
    EXPECT_NEAR(ao(x, 26), ref, 4 * 0.016) << x;
  }
}

TEST(ScreenSpaceLimit, OpenPlaneIsExactlyOne) {
  for (double tilt : {0.0, 60.0, 89.0}) {
    const SceneFixture f("plane", 96, 54, {{"tilt", tilt}, {"azimuth", 30}});
    for (float radius : {0.01f, 1.0f, 1e30f})
      EXPECT_EQ(
          min_valid(screen_space_limit(f.g, settings(radius, kScreenSpaceLimitUnbounded, 16)), f.g),
          1.0f)
          << tilt << " " << radius;
  }
}

TEST(ScreenSpaceLimit, ZeroThicknessGivesOne) {
  const SceneFixture f("blocks", 96, 54);
  const Image ao = screen_space_limit(f.g, settings(0.5f, 0.0f, 16));
  for (float v : ao.pixels()) ASSERT_EQ(v, 1.0f);
}

// The same rays at every thickness (same seed): a thicker solid only adds blocked rays, so
// the AO falls pixel by pixel; thin objects (blocks) separate the settings.
TEST(ScreenSpaceLimit, ThickerSolidsOccludeMore) {
  const SceneFixture f("blocks", 128, 72);
  Image previous = screen_space_limit(f.g, settings(0.5f, 0.0f, 16));
  double previous_mean = 1.0;
  for (float thickness : {0.02f, 0.1f, 0.5f, kScreenSpaceLimitUnbounded}) {
    const Image ao = screen_space_limit(f.g, settings(0.5f, thickness, 16));
    double mean = 0;
    for (std::size_t i = 0; i < ao.pixels().size(); ++i) {
      ASSERT_LE(ao.pixels()[i], previous.pixels()[i]) << thickness << " at " << i;
      ASSERT_GE(ao.pixels()[i], 0.0f);
      mean += ao.pixels()[i];
    }
    mean /= double(ao.pixels().size());
    EXPECT_LT(mean, previous_mean) << thickness;
    previous = ao, previous_mean = mean;
  }
}

// Rays that leave the image count as unoccluded: the wall scene cut below its crease shows
// the floor only, and the floor next to the cut then sees no wall at all.
TEST(ScreenSpaceLimit, RaysLeavingTheImageAreUnoccluded) {
  const SceneFixture full("wall", 160, 90, {{"radius", 1.0}});
  int crease = 0;  // the row of the crease: the darkest of the middle column
  for (int y = 0; y < 90; ++y)
    if (full.scene.reference(80, y) < full.scene.reference(80, crease)) crease = y;
  ASSERT_GT(crease, 10);
  const int top = crease + 2;
  const Crop cut(full.scene, top, 90 - top);
  const Image ao = screen_space_limit(cut.g, settings(1.0f, kScreenSpaceLimitUnbounded, 16));
  for (int x = 0; x < 160; ++x) {
    ASSERT_LT(cut.reference(x, 0), 0.9f);  // the wall occludes there in truth
    EXPECT_EQ(ao(x, 0), 1.0f) << x;        // but it is out of the image
  }
}

// The seed moves the noise, not the expected value.
TEST(ScreenSpaceLimit, SeedChangesNoiseNotMean) {
  const SceneFixture f("crease", 96, 54);
  ScreenSpaceLimitSettings a = settings(1.0f, kScreenSpaceLimitUnbounded, 16), b = a;
  b.seed = 7;
  const Image ia = screen_space_limit(f.g, a), ib = screen_space_limit(f.g, b);
  double mean_a = 0, mean_b = 0;
  int differ = 0;
  for (std::size_t i = 0; i < ia.pixels().size(); ++i) {
    mean_a += ia.pixels()[i], mean_b += ib.pixels()[i];
    differ += ia.pixels()[i] != ib.pixels()[i];
  }
  EXPECT_GT(differ, 100);
  // 5184 pixels at N = 16: the mean's standard deviation is at most √(0.25/16/5184) ≈ 1.7e-3.
  const double pixels = double(ia.pixels().size());
  EXPECT_NEAR(mean_a / pixels, mean_b / pixels, 4 * 1.7e-3 * std::sqrt(2.0));
}

// One pass at several thicknesses gives each thickness's run bit for bit, in any order, with
// zero (nothing occludes) and the height field among them.
TEST(ScreenSpaceLimit, ThicknessesInOnePassEqualSeparateRuns) {
  const SceneFixture f("blocks", 96, 54);
  const ScreenSpaceLimitSettings s = settings(0.5f, 0.0f, 16);
  const std::vector<float> thicknesses = {0.25f, kScreenSpaceLimitUnbounded, 0.0f, 0.05f};
  const std::vector<Image> together = screen_space_limit_thicknesses(f.g, s, thicknesses);
  ASSERT_EQ(together.size(), thicknesses.size());
  for (std::size_t i = 0; i < thicknesses.size(); ++i) {
    ScreenSpaceLimitSettings one = s;
    one.thickness = thicknesses[i];
    EXPECT_EQ(together[i].pixels(), screen_space_limit(f.g, one).pixels()) << thicknesses[i];
  }
  EXPECT_EQ(mean_value(together[2]), 1.0);                      // zero thickness: nothing occludes
  EXPECT_LT(mean_value(together[1]), mean_value(together[0]));  // the height field occludes most
}

TEST(ScreenSpaceLimit, ThicknessesAreValidatedLikeTheSetting) {
  const SceneFixture f("blocks", 16, 9);
  const ScreenSpaceLimitSettings s = settings(0.5f, 0.0f, 4);
  EXPECT_NE(invalid_argument_message([&] {
              screen_space_limit_thicknesses(f.g, s, {});
            }).find("thicknesses"),
            std::string::npos);
  const std::string negative = invalid_argument_message([&] {
    screen_space_limit_thicknesses(f.g, s, {0.1f, -1.0f});
  });
  EXPECT_NE(negative.find("thickness"), std::string::npos) << negative;
  EXPECT_NE(negative.find("-1"), std::string::npos) << negative;
}

TEST(ScreenSpaceLimit, IsMarkedAsABound) {
  EXPECT_TRUE(screen_space_limit_method().bound);
  EXPECT_TRUE(screen_space_limit_method().needs_normal);
  EXPECT_FALSE(find_method("hbao").bound);
}

}  // namespace
}  // namespace aolab
