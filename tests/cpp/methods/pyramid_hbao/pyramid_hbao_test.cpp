// Known answers for Pyramid HBAO (Astapov et al. 2021): eq. 7–8 on a depth step read from
// level 0 and from level 1 of the pyramid, the sampling pattern of §3.5, levels, the blur.
// What every method promises (planes, background, threads, settings errors) is
// conformance_test's.
#include "core/methods/pyramid_hbao/pyramid_hbao.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <iostream>
#include <numbers>
#include <vector>

#include "core/filters/blur.h"
#include "core/methods/pyramid_hbao/depth_pyramid.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::expect_other_noise_same_mean;
using testing::mean_value;
using testing::min_valid;
using testing::SceneFixture;

PyramidHbaoSettings no_randomness(PyramidHbaoSettings s = {}) {
  s.rotation = s.random_directions = s.random_start = false;
  s.gaussian_filter = false;
  return s;
}

// Eq. 8's term for a sample at view-space position S seen from P with normal n (eq. 7 W;
// with `attenuate` false W = 1 up to and including r = R, attenuation = none).
double weighted_contribution(const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3& s,
                             double radius, bool attenuate = true) {
  const glm::dvec3 d = s - p;
  const double r = glm::length(d);
  if (attenuate ? r >= radius : r > radius) return 0.0;
  const double w = attenuate ? std::max(0.0, 1.0 - r / radius) : 1.0;
  return w * std::max(0.0, glm::dot(n, d) / r);
}

glm::dvec3 view_point(const CameraIntrinsics& c, double px, double py, double depth) {
  return {(px - c.cx) / c.fx * depth, -(py - c.cy) / c.fy * depth, -depth};
}

// The `step` scene (floor at depth 50 on the left half, a slab 0.5 nearer on the right,
// seen from above) with D = 4 axis directions and no randomness: only the direction towards
// the slab (+x) sees an occluder, so A = 1 − ¼ max_i W(r_i)·sin α_i (eqs. 7, 8, §3.4 step 3)
// over that direction's samples, computed here in double precision from the same texels.
class PyramidHbaoStep : public ::testing::Test {
 protected:
  SceneFixture f{"step", 512, 64};
  PyramidHbaoSettings s = [] {
    PyramidHbaoSettings st = no_randomness();
    st.directions = 4;
    st.radius = 1.0f;
    return st;
  }();
  static constexpr int kRow = 32, kEdge = 256;  // first slab column

  glm::dvec3 normal(int x, int y) const {
    return glm::normalize(
        glm::dvec3(f.scene.normal(x, y, 0), f.scene.normal(x, y, 1), f.scene.normal(x, y, 2)));
  }
  glm::dvec3 position(int x, int y) const {
    return view_point(f.g.camera, x + 0.5, y + 0.5, f.scene.depth(x, y));
  }
};

TEST_F(PyramidHbaoStep, LevelZeroSamplesGiveEquationEight) {
  s.levels = 1;  // the depth buffer only, 1-pixel steps
  s.samples = 64;
  const int x = 250;
  const glm::dvec3 p = position(x, kRow), n = normal(x, kRow);
  // Samples at t = 1, 2, … pixels along +x, up to the projected radius R·fx/d.
  const double reach = s.radius * f.g.camera.fx / f.scene.depth(x, kRow);
  double best = 0;
  for (int t = 1; t <= s.samples && t <= reach; ++t)
    best = std::max(best, weighted_contribution(p, n, position(x + t, kRow), s.radius));
  ASSERT_GT(best, 0.1);  // the slab edge, 6 px away, is a strong occluder
  const Image ao = pyramid_hbao(f.g, s);
  EXPECT_NEAR(ao(x, kRow), 1.0 - best / 4, 1e-5);
  EXPECT_EQ(ao(kEdge + 2, kRow), 1.0f);  // the slab top sees nothing above it
}

// attenuation = none (W = 1 within R, the reference's cut-off): eq. 8 keeps the highest
// sample above the tangent plane within R, which outweighs every attenuated one.
TEST_F(PyramidHbaoStep, WithoutAttenuationEquationEightTakesTheHighestSample) {
  s.levels = 1;
  s.samples = 64;
  s.attenuation = int(PyramidHbaoAttenuation::None);
  const int x = 250;
  const glm::dvec3 p = position(x, kRow), n = normal(x, kRow);
  const double reach = s.radius * f.g.camera.fx / f.scene.depth(x, kRow);
  double best = 0, best_linear = 0;
  for (int t = 1; t <= s.samples && t <= reach; ++t) {
    best = std::max(best, weighted_contribution(p, n, position(x + t, kRow), s.radius, false));
    best_linear =
        std::max(best_linear, weighted_contribution(p, n, position(x + t, kRow), s.radius));
  }
  ASSERT_GT(best, best_linear + 0.05);
  const Image ao = pyramid_hbao(f.g, s);
  EXPECT_NEAR(ao(x, kRow), 1.0 - best / 4, 1e-5);
  EXPECT_EQ(ao(kEdge + 2, kRow), 1.0f);
}

// Level 1 (K = 3): after S = 4 one-pixel reads, the step triples and the reads come from
// the pyramid — each position restored at the texel's centroid and averaged depth (§3.4
// step 2a). Texel 85 of row 10 averages floor column 255 with slab columns 256–257: a point
// a third of the way up the step.
TEST_F(PyramidHbaoStep, LevelOneSamplesAreRestoredAtTexelCentroids) {
  s.levels = 2;
  s.samples = 4;
  const int x = 245;
  const glm::dvec3 p = position(x, kRow), n = normal(x, kRow);
  const DepthPyramid pyramid(f.g, 3, 2);
  double best = 0;
  for (double t : {1.0, 2.0, 3.0, 4.0})  // level 0: floor only
    best = std::max(best, weighted_contribution(p, n, position(x + int(t), kRow), s.radius));
  EXPECT_EQ(best, 0.0);
  for (double t : {7.0, 10.0, 13.0, 16.0}) {  // level 1: columns 252, 255, 258, 261
    const PyramidTexel& texel = pyramid.level(1)((x + int(t)) / 3, kRow / 3);
    best =
        std::max(best, weighted_contribution(
                           p, n, view_point(f.g.camera, texel.x, texel.y, texel.depth), s.radius));
  }
  const PyramidTexel& mixed = pyramid.level(1)(85, kRow / 3);
  EXPECT_FLOAT_EQ(mixed.depth, (50.0f + 2 * 49.5f) / 3);
  EXPECT_EQ(mixed.x, 256.5f);
  ASSERT_GT(best, 0.05);
  const Image ao = pyramid_hbao(f.g, s);
  EXPECT_NEAR(ao(x, kRow), 1.0 - best / 4, 1e-5);
}

TEST(PyramidHbao, OcclusionGrowsWithRadiusAndStaysInRange) {
  SceneFixture f("crease", 160, 90);
  double previous = 1.0;
  for (float radius : {0.25f, 0.5f, 1.0f, 2.0f}) {
    PyramidHbaoSettings s = no_randomness();
    s.radius = radius;
    const Image ao = pyramid_hbao(f.g, s);
    for (float v : ao.pixels()) {
      ASSERT_GE(v, 0.0f);
      ASSERT_LE(v, 1.0f);
    }
    EXPECT_LT(mean_value(ao), previous) << "radius " << radius;
    previous = mean_value(ao);
  }
}

// attenuation = none against the closed form of Cycles' AO beside a crease
// (cycles_ao_beside_wall): W = 1 is the reference's weight, so the MAE drops; per pixel it
// can only darken (every term of eq. 8 gains weight, and the Gaussian has positive weights).
TEST(PyramidHbao, NoAttenuationIsCloserToCyclesBesideACrease) {
  for (const char* scene : {"wall", "crease"}) {
    SceneFixture f(scene, 160, 90);
    PyramidHbaoSettings linear, none;
    none.attenuation = int(PyramidHbaoAttenuation::None);
    const Image a = pyramid_hbao(f.g, linear), b = pyramid_hbao(f.g, none);
    for (std::size_t i = 0; i < a.pixels().size(); ++i)
      ASSERT_LE(b.pixels()[i], a.pixels()[i] + 1e-6f) << scene << " pixel " << i;
    const double e_linear = testing::mae_against_reference(a, f);
    const double e_none = testing::mae_against_reference(b, f);
    std::cout << "[attenuation] " << scene << " MAE linear " << e_linear << ", none " << e_none
              << "\n";
    EXPECT_LT(e_none, e_linear) << scene;
  }
}

TEST(PyramidHbao, SeedChangesNoiseButNotMean) {
  SceneFixture f("blocks", 200, 120);
  PyramidHbaoSettings s0, s1;
  s0.radius = s1.radius = 0.5f;
  s0.gaussian_filter = s1.gaussian_filter = false;
  s1.seed = 7;
  expect_other_noise_same_mean(pyramid_hbao(f.g, s0), pyramid_hbao(f.g, s1), 2e-3);
}

// §3.5's pattern: uniform directions when everything is off; one random direction per
// sector; one blue-noise rotation shared by the directions of a pixel, tiled every 32
// pixels; start multipliers in [0.5, 1.5).
TEST(PyramidHbao, DirectionsFollowTheSettings) {
  constexpr int kD = 8;
  const double sector = 2 * std::numbers::pi / kD;
  std::vector<PyramidHbaoDirection> dirs(kD), other(kD);
  auto angle = [](const PyramidHbaoDirection& d) {
    const double a = std::atan2(double(d.sin_theta), double(d.cos_theta));
    return a < 0 ? a + 2 * std::numbers::pi : a;
  };

  PyramidHbaoSettings s = no_randomness();
  s.directions = kD;
  pyramid_hbao_directions(s, 5, 9, dirs.data());
  for (int k = 0; k < kD; ++k) {
    EXPECT_NEAR(angle(dirs[k]), sector * k, 1e-6);
    EXPECT_EQ(dirs[k].start, 1.0f);
  }

  s.random_directions = true;
  for (int x = 0; x < 50; ++x) {
    pyramid_hbao_directions(s, x, 3, dirs.data());
    for (int k = 0; k < kD; ++k) {
      EXPECT_GE(angle(dirs[k]), sector * k - 1e-6);
      EXPECT_LT(angle(dirs[k]), sector * (k + 1) + 1e-6);
    }
  }

  s = no_randomness();
  s.directions = kD;
  s.rotation = true;
  pyramid_hbao_directions(s, 5, 9, dirs.data());
  const double rotation = angle(dirs[0]);
  for (int k = 0; k < kD; ++k)
    EXPECT_NEAR(std::remainder(angle(dirs[k]) - sector * k - rotation, 2 * std::numbers::pi), 0,
                1e-5);
  pyramid_hbao_directions(s, 5 + 32, 9 - 64, other.data());
  EXPECT_EQ(dirs[0].cos_theta, other[0].cos_theta);
  pyramid_hbao_directions(s, 6, 9, other.data());
  EXPECT_NE(dirs[0].cos_theta, other[0].cos_theta);

  s.random_start = true;
  double sum = 0;
  int n = 0;
  for (int y = 0; y < 40; ++y) {
    pyramid_hbao_directions(s, 3, y, dirs.data());
    for (const auto& d : dirs) {
      EXPECT_GE(d.start, kPyramidHbaoStartMin);
      EXPECT_LT(d.start, kPyramidHbaoStartMax);
      sum += d.start, ++n;
    }
  }
  EXPECT_NEAR(sum / n, 1.0, 0.05);
}

// L = 0 marches every level down to 1×1 (stopping at the projected radius); so does any L
// at least that deep.
TEST(PyramidHbao, DerivedLevelsEqualAllLevels) {
  SceneFixture f("blocks", 160, 90);
  PyramidHbaoSettings s;
  s.radius = 2.0f;
  s.gaussian_filter = false;
  const Image derived = pyramid_hbao(f.g, s);
  s.levels = DepthPyramid::full_levels(160, 90, s.reduction);
  EXPECT_EQ(derived.pixels(), pyramid_hbao(f.g, s).pixels());
  s.levels = 32;
  EXPECT_EQ(derived.pixels(), pyramid_hbao(f.g, s).pixels());
  s.levels = 2;  // a cap: less reach, less occlusion
  EXPECT_GT(mean_value(pyramid_hbao(f.g, s)), mean_value(derived));
}

TEST(PyramidHbao, GaussianFilterIsTheSharedBlurWithItsDefaults) {
  SceneFixture f("blocks", 160, 90);
  PyramidHbaoSettings raw;
  raw.radius = 0.5f;
  raw.gaussian_filter = false;
  PyramidHbaoSettings filtered = raw;
  filtered.gaussian_filter = true;
  EXPECT_EQ(pyramid_hbao(f.g, filtered).pixels(),
            gaussian_blur(pyramid_hbao(f.g, raw).view(), f.g, BlurSettings{}).pixels());
  EXPECT_EQ(BlurSettings{}.sigma, 1.5f);  // §3.5: σ = 1.5, 5 samples per direction
  EXPECT_EQ(BlurSettings{}.taps, 5);
}

}  // namespace
}  // namespace aolab
