// Known answers for Scalable AO (McGuire, Mara, Luebke 2012): the rotated-grid z pyramid, the
// mip selection (no tap leaves level 0 below the switch distance), the shared estimator (at
// full resolution without the filter SAO is Alchemy AO bit for bit), the quad normals on a
// plane, the depth-aware filter, exactly 1 where nothing lies within r, very large radii,
// the seed. What every method promises is conformance_test's.
#include "core/methods/sao/sao.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/methods/alchemy/alchemy.h"
#include "core/methods/sao/sao_blur.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::SceneFixture;

SaoSettings raw(float radius) {
  SaoSettings s;
  s.radius = radius;
  s.filter = false;
  return s;
}

// §2.2: z_{m+1}(x, y) = z_m(2x + ((y & 1) ⊕ 1), 2y + ((x & 1) ⊕ 1)) (the reference code:
// without ⊕ 1), coordinates clamped, levels ⌈w/2⌉ × ⌈h/2⌉; each texel remembers its pixel.
TEST(Sao, PyramidIsTheRotatedGrid) {
  const int w = 37, h = 23;
  const Image values = testing::random_image(w, h, 5, 1.0f, 9.0f);
  const std::vector<float> depth(values.pixels().begin(), values.pixels().end());
  for (SaoGrid grid : {SaoGrid::Paper, SaoGrid::Reference}) {
    const std::vector<SaoZLevel> levels = sao_z_pyramid(depth, w, h, 6, grid, 2);
    ASSERT_EQ(levels.size(), 7u);
    const int flip = grid == SaoGrid::Paper ? 1 : 0;
    for (std::size_t m = 1; m < levels.size(); ++m) {
      const SaoZLevel &fine = levels[m - 1], &coarse = levels[m];
      EXPECT_EQ(coarse.width, (fine.width + 1) / 2);
      EXPECT_EQ(coarse.height, (fine.height + 1) / 2);
      for (int y = 0; y < coarse.height; ++y)
        for (int x = 0; x < coarse.width; ++x) {
          const int fx = std::min(2 * x + ((y & 1) ^ flip), fine.width - 1);
          const int fy = std::min(2 * y + ((x & 1) ^ flip), fine.height - 1);
          const std::size_t t = std::size_t(y) * coarse.width + x;
          EXPECT_EQ(coarse.depth[t], fine.depth[std::size_t(fy) * fine.width + fx]);
          EXPECT_EQ(coarse.depth[t], depth[std::size_t(coarse.source[t])]);
        }
    }
  }
}

// One estimator for both methods: at full resolution, without the filter and with no bias
// (SAO's is a distance, Alchemy's a multiple of depth), SAO is Alchemy AO bit for bit.
TEST(Sao, FullResolutionUnfilteredIsAlchemy) {
  SceneFixture f("blocks", 128, 72);
  for (int falloff : {0, 1}) {
    SaoSettings s = raw(0.5f);
    s.max_mip_level = 0;
    s.bias = 0.0f;
    s.falloff = falloff;
    s.samples = 13;
    s.epsilon = 1e-3f;
    s.intensity = 1.3f;
    s.contrast = 1.2f;
    AlchemySettings a;
    a.radius = s.radius;
    a.bias = 0.0f;
    a.falloff = falloff;
    a.samples = s.samples;
    a.epsilon = s.epsilon;
    a.intensity = s.intensity;
    a.contrast = s.contrast;
    EXPECT_EQ(sao(f.g, s).pixels(), alchemy(f.g, a).pixels()) << falloff;
  }
}

// m_i = clamp(⌊log2 h_i⌋ − q', 0, L_max): with q' = 10 no tap of a 160-px image reaches level 1,
// so the pyramid changes nothing; with q' = 0 most taps read coarse levels, and with the
// taps placed where their depth came from the result stays near full resolution's.
TEST(Sao, MipSelectionFollowsTheSwitchDistance) {
  SceneFixture f("blocks", 160, 90);
  SaoSettings full = raw(0.5f);
  full.max_mip_level = 0;
  SaoSettings late = raw(0.5f);
  late.log_max_offset = 10;
  const Image a = sao(f.g, full);
  EXPECT_EQ(a.pixels(), sao(f.g, late).pixels());
  SaoSettings early = raw(0.5f);
  early.log_max_offset = 0;
  const Image b = sao(f.g, early);
  EXPECT_NE(a.pixels(), b.pixels());
  EXPECT_NEAR(testing::mean_value(a), testing::mean_value(b), 0.01);
}

// The paper's normals (cross product of the quad's position differences) on a plane are the
// plane's normal.
TEST(Sao, QuadNormalsOfAPlaneAreItsNormal) {
  SceneFixture f("plane", 96, 54, {{"tilt", 50.0}, {"azimuth", 20.0}});
  const Buffer<float> depth = depth_with_background_as_nan(f.g);
  const Image gb = prepared_normals(f.g);
  const Image quad = sao_quad_normals(f.g, depth, gb.view(), 2);
  for (int y = 0; y < 54; ++y)
    for (int x = 0; x < 96; ++x)
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(quad(x, y, c), gb(x, y, c), 2e-3) << x << " " << y;
}

// The filter is a weighted mean: a constant image comes back bit for bit; across a depth
// step larger than the edge depth nothing mixes; over one depth it smooths noise.
TEST(Sao, FilterIsADepthAwareMean) {
  const int w = 40, h = 20;
  std::vector<float> depth(std::size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) depth[std::size_t(y) * w + x] = x < 20 ? 1.0f : 5.0f;
  SaoBlurParams p;
  p.edge_depth = 0.5f;
  Image constant(w, h, 1, 0.37f);
  sao_bilateral_filter(constant, depth, p, 2, nullptr);
  for (float v : constant.pixels()) ASSERT_EQ(v, 0.37f);
  Image halves(w, h, 1, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < 20; ++x) halves(x, y) = 0.2f;
  const Image before = halves;
  sao_bilateral_filter(halves, depth, p, 2, nullptr);
  EXPECT_EQ(halves.pixels(), before.pixels());
  Image noise = testing::random_image(w, h, 3);
  const std::vector<float> flat(depth.size(), 2.0f);
  const double mean = testing::mean_value(noise);
  sao_bilateral_filter(noise, flat, p, 2, nullptr);
  EXPECT_NEAR(testing::mean_value(noise), mean, 0.02);
  double var = 0.0;
  for (float v : noise.pixels()) var += (v - mean) * (v - mean);
  EXPECT_LT(var / double(noise.pixels().size()), 1.0 / 12.0 / 4.0);  // uniform noise: 1/12
}

// Nothing within r: exactly 1, filtered or not, and from every level.
TEST(Sao, NothingWithinTheRadiusIsOne) {
  SceneFixture f("ceiling", 256, 144);
  SaoSettings s;
  s.radius = 0.9f;
  s.samples = 30;
  EXPECT_EQ(testing::min_valid(sao(f.g, s), f.g), 1.0f);
  s.log_max_offset = 0;
  s.normals = int(SaoNormals::Depth);
  EXPECT_EQ(testing::min_valid(sao(f.g, s), f.g), 1.0f);
}

// Beyond the screen every tap leaves the image; under a pixel every tap is the pixel itself.
TEST(Sao, ExtremeRadiiAreStable) {
  SceneFixture f("blocks", 96, 54);
  for (float radius : {1e-12f, 1e-6f, 1e6f, 1e12f, 1e20f, 1e30f}) {
    SaoSettings s;
    s.radius = radius;
    EXPECT_EQ(testing::min_valid(sao(f.g, s), f.g), 1.0f) << radius;
  }
  for (float radius : {3.0f, 30.0f, 300.0f}) {
    SaoSettings s;
    s.radius = radius;
    const Image ao = sao(f.g, s);
    for (float v : ao.pixels()) ASSERT_TRUE(v >= 0.0f && v <= 1.0f) << radius;
  }
}

TEST(Sao, SeedChangesNoiseButNotMean) {
  SceneFixture f("blocks", 160, 90);
  SaoSettings s0 = raw(0.5f);
  SaoSettings s1 = s0;
  s1.seed = 7;
  testing::expect_other_noise_same_mean(sao(f.g, s0), sao(f.g, s1), 3e-3);
}

}  // namespace
}  // namespace aolab
