// Known answers for Alchemy AO (McGuire et al. 2011): the estimator equals its equation
// evaluated independently in double, exactly 1 wherever no surface lies within r (open
// planes for any bias and ε, a ceiling beyond r, a floor farther than r from a wall), the
// contrast and intensity, the spiral, very large radii, the seed. What every method promises
// (background, threads, settings errors) is conformance_test's.
#include "core/methods/alchemy/alchemy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::SceneFixture;

AlchemySettings fixed(float radius, int samples) {
  AlchemySettings s;
  s.radius = radius;
  s.samples = samples;
  s.random_rotation = false;
  return s;
}

// The table of τ and the spiral it drives (SAO §2.3): α_i = (i + ½)/s, θ_i = 2π·α_i·τ.
TEST(AlchemySpiral, TurnsAndTapsFollowTheTable) {
  EXPECT_EQ(spiral_turns(1, 0), 1);
  EXPECT_EQ(spiral_turns(9, 0), 2);
  EXPECT_EQ(spiral_turns(12, 0), 5);
  EXPECT_EQ(spiral_turns(98, 0), 27);
  EXPECT_EQ(spiral_turns(9, 7), 7);
  const SpiralTaps taps(12, 0);
  ASSERT_EQ(taps.size(), 12);
  const double phi = 0.7;
  for (int i = 0; i < 12; ++i) {
    const double alpha = (i + 0.5) / 12, theta = 2 * std::numbers::pi * alpha * 5 + phi;
    float c, s;
    taps.direction(i, float(std::cos(phi)), float(std::sin(phi)), c, s);
    EXPECT_FLOAT_EQ(taps.alpha(i), float(alpha));
    EXPECT_NEAR(c, std::cos(theta), 1e-6);
    EXPECT_NEAR(s, std::sin(theta), 1e-6);
  }
}

// The estimator (§3) evaluated independently in double, tap by tap, on the `blocks` scene:
// A = max(0, 1 − (2σr/s) Σ [v·v < r²] max(0, v·n − β·d)/(v·v + ε·r²))^k.
TEST(Alchemy, EstimatorIsTheEquation) {
  SceneFixture f("blocks", 96, 54);
  AlchemySettings s = fixed(0.6f, 7);
  s.intensity = 0.8f;
  s.contrast = 1.5f;
  s.bias = 1e-3f;
  s.epsilon = 0.01f;
  const Image ao = alchemy(f.g, s);
  const CameraIntrinsics& cam = f.g.camera;
  const double r = s.radius, pi = std::numbers::pi;
  const auto position = [&](int x, int y) {
    const double d = f.scene.depth(x, y);
    return glm::dvec3((x + 0.5 - cam.cx) * d / cam.fx, -(y + 0.5 - cam.cy) * d / cam.fy, -d);
  };
  double total = 0.0;
  int pixels = 0, close = 0;
  for (int y = 0; y < 54; ++y)
    for (int x = 0; x < 96; ++x) {
      if (!f.g.valid(x, y)) continue;
      const double d = f.scene.depth(x, y);
      const glm::dvec3 c = position(x, y);
      const glm::dvec3 n(f.scene.normal(x, y, 0), f.scene.normal(x, y, 1), f.scene.normal(x, y, 2));
      double sum = 0.0;
      for (int i = 0; i < s.samples; ++i) {
        const double alpha = (i + 0.5) / s.samples, theta = 2 * pi * alpha * spiral_turns(7, 0);
        const double px = x + 0.5 + alpha * std::cos(theta) * r * cam.fx / d;
        const double py = y + 0.5 - alpha * std::sin(theta) * r * cam.fy / d;
        if (px < 0 || px >= 96 || py < 0 || py >= 54) continue;
        const int sx = int(px), sy = int(py);
        if ((sx == x && sy == y) || !f.g.valid(sx, sy)) continue;
        const glm::dvec3 v = position(sx, sy) - c;
        const double vv = glm::dot(v, v);
        if (vv >= r * r) continue;
        sum += std::max(0.0, glm::dot(v, n) - s.bias * d) / (vv + s.epsilon * r * r);
      }
      const double want = std::pow(std::max(0.0, 1.0 - 2.0 * s.intensity * r / s.samples * sum),
                                   double(s.contrast));
      const double err = std::abs(ao(x, y) - want);
      total += err, ++pixels, close += err < 1e-4;
    }
  ASSERT_GT(pixels, 3000);
  EXPECT_LT(total / pixels, 2e-5);
  EXPECT_GT(close, pixels * 995 / 1000);
}

// v·n = 0 on a plane: every tap's term is 0, for any bias and ε (the tangent test removes the
// rounding), so an open plane is exactly 1 at any tilt.
TEST(Alchemy, OpenPlaneIsOneWithoutBias) {
  for (double tilt : {0.0, 60.0, 85.0})
    for (int falloff : {0, 1}) {
      SceneFixture f("plane", 128, 72, {{"tilt", tilt}, {"azimuth", 30.0}});
      AlchemySettings s;
      s.radius = 2.0f;
      s.bias = 0.0f;
      s.epsilon = 0.0f;
      s.samples = 32;
      s.falloff = falloff;
      EXPECT_EQ(testing::min_valid(alchemy(f.g, s), f.g), 1.0f) << tilt << " " << falloff;
    }
}

// Taps farther than r are dropped: under a ceiling beyond r, and on a floor farther than r
// from a wall (where Cycles' AO is 1 too), nothing occludes.
TEST(Alchemy, NothingWithinTheRadiusIsOne) {
  SceneFixture ceiling("ceiling", 256, 144);
  EXPECT_EQ(testing::min_valid(alchemy(ceiling.g, fixed(0.9f, 24)), ceiling.g), 1.0f);
  SceneFixture wall("wall", 256, 144, {{"radius", 1.0}});
  AlchemySettings s = fixed(1.0f, 24);
  s.random_rotation = true;
  const Image ao = alchemy(wall.g, s);
  int open = 0, one = 0, occluded = 0;
  for (int y = 0; y < 144; ++y)
    for (int x = 0; x < 256; ++x) {
      if (!wall.g.valid(x, y)) continue;
      if (wall.scene.reference(x, y) == 1.0f) ++open, one += ao(x, y) == 1.0f;
      if (wall.scene.reference(x, y) < 0.8f) occluded += ao(x, y) < 1.0f;
    }
  ASSERT_GT(open, 5000);
  EXPECT_GT(one, open * 999 / 1000);
  EXPECT_GT(occluded, 500);  // and near the crease it does occlude
}

// k is an exponent of the result and σ scales the sum: A(k) = A(1)^k, 1 − A(2σ) = 2(1 − A(σ)).
TEST(Alchemy, ContrastAndIntensity) {
  SceneFixture f("blocks", 96, 54);
  const AlchemySettings base = fixed(0.5f, 12);
  AlchemySettings k2 = base, s2 = base;
  k2.contrast = 2.0f;
  s2.intensity = 2.0f;
  const Image a = alchemy(f.g, base), b = alchemy(f.g, k2), c = alchemy(f.g, s2);
  int checked = 0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i) {
    EXPECT_NEAR(b.pixels()[i], a.pixels()[i] * a.pixels()[i], 1e-6);
    if (c.pixels()[i] > 0.0f) {
      EXPECT_NEAR(1.0 - c.pixels()[i], 2.0 * (1.0 - a.pixels()[i]), 1e-5);
      checked += a.pixels()[i] < 1.0f;
    }
  }
  EXPECT_GT(checked, 200);
}

// Beyond the screen every tap leaves the image (AO exactly 1); under a pixel every tap falls
// back on the pixel itself (AO exactly 1); in between the result stays finite.
TEST(Alchemy, ExtremeRadiiAreStable) {
  SceneFixture f("blocks", 96, 54);
  for (float radius : {1e-12f, 1e-6f, 1e6f, 1e12f, 1e20f, 1e30f}) {
    AlchemySettings s;
    s.radius = radius;
    EXPECT_EQ(testing::min_valid(alchemy(f.g, s), f.g), 1.0f) << radius;
  }
  for (float radius : {3.0f, 30.0f, 300.0f}) {
    AlchemySettings s;
    s.radius = radius;
    const Image ao = alchemy(f.g, s);
    for (float v : ao.pixels()) ASSERT_TRUE(v >= 0.0f && v <= 1.0f) << radius;
  }
}

TEST(Alchemy, SeedChangesNoiseButNotMean) {
  SceneFixture f("blocks", 160, 90);
  AlchemySettings s0;
  s0.radius = 0.5f;
  AlchemySettings s1 = s0;
  s1.seed = 7;
  testing::expect_other_noise_same_mean(alchemy(f.g, s0), alchemy(f.g, s1), 3e-3);
}

}  // namespace
}  // namespace aolab
