// VAO++ (Bokšanský et al. 2017 §4; core/methods/vao_pp/vao_pp.h, core/methods/vao_pp/bilateral.h):
// eq. 3 at known points, the adaptive sample counts of §4.1, the filter on constant images and
// depth edges, the culling pre-pass, colour bleeding, each extension switchable, statistics,
// hard inputs. What every method promises (planes, background, threads, settings errors) is
// conformance_test's.
#include "core/methods/vao_pp/vao_pp.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/methods/registry.h"
#include "core/methods/vao/vao.h"
#include "core/methods/vao_pp/bilateral.h"
#include "tests/cpp/methods/vao/convex_room.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::SceneFixture;

double mean_abs_difference(const Image& a, const Image& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i) s += std::abs(a.pixels()[i] - b.pixels()[i]);
  return s / double(a.pixels().size());
}

TEST(VaoPpLuminance, Eq3AtKnownPoints) {
  // threshold 0.5, width 0.3 (Figure 9): the ramp runs over lum in [0.2, 0.8].
  for (float sigma : {0.5f, 1.0f, 3.0f}) {
    EXPECT_EQ(vao_pp_luminance_factor(0.0f, 0.5f, 0.3f, sigma), 1.0f);
    EXPECT_EQ(vao_pp_luminance_factor(0.2f, 0.5f, 0.3f, sigma), 1.0f);
    EXPECT_NEAR(vao_pp_luminance_factor(0.5f, 0.5f, 0.3f, sigma), std::pow(0.5f, sigma), 1e-6);
    EXPECT_NEAR(vao_pp_luminance_factor(0.35f, 0.5f, 0.3f, sigma), std::pow(0.75f, sigma), 1e-6);
    EXPECT_EQ(vao_pp_luminance_factor(0.8f, 0.5f, 0.3f, sigma), 0.0f);
    EXPECT_EQ(vao_pp_luminance_factor(5.0f, 0.5f, 0.3f, sigma), 0.0f);
  }
  const float white[3] = {1, 1, 1}, red[3] = {0.8f, 0.1f, 0.2f};
  EXPECT_NEAR(vao_pp_lum(white, 0), 1.0f, 1e-6);
  EXPECT_NEAR(vao_pp_lum(red, 0), 0.2126f * 0.8f + 0.7152f * 0.1f + 0.0722f * 0.2f, 1e-7);
  EXPECT_EQ(vao_pp_lum(red, 1), 0.8f);  // HSV value
}

TEST(VaoPpAdaptive, SamplesDoubleWithTheDiscArea) {
  const float m = 0.01f;
  EXPECT_EQ(vao_pp_adaptive_samples(0.001f, m, 32), 2);
  EXPECT_EQ(vao_pp_adaptive_samples(m, m, 32), 2);
  EXPECT_EQ(vao_pp_adaptive_samples(m * 1.42f, m, 32), 4);  // area x 2.02
  EXPECT_EQ(vao_pp_adaptive_samples(m * 1.41f, m, 32), 2);  // area x 1.99
  EXPECT_EQ(vao_pp_adaptive_samples(m * 2.0f, m, 32), 8);   // area x 4
  EXPECT_EQ(vao_pp_adaptive_samples(m * 2.9f, m, 32), 16);  // area x 8.4
  EXPECT_EQ(vao_pp_adaptive_samples(m * 4.0f, m, 32), 32);  // area x 16
  EXPECT_EQ(vao_pp_adaptive_samples(m * 100.0f, m, 32), 32);
  EXPECT_EQ(vao_pp_adaptive_samples(m * 100.0f, m, 8), 8);
  EXPECT_EQ(vao_pp_adaptive_samples(INFINITY, m, 16), 16);
  EXPECT_EQ(vao_pp_adaptive_samples(NAN, m, 16), 2);
}

TEST(CrossBilateral, KeepsConstantImagesAndDepthEdges) {
  SceneFixture f("step", 120, 80);  // a depth edge across the frame
  Image ones(120, 80, 4, 1.0f);
  const Image out = cross_bilateral_filter(ones.view(), f.g, 7, 2.0f, 0.1f, 2);
  EXPECT_EQ(out.pixels(), ones.pixels());  // bit for bit
  Image c(120, 80, 1, 0.37f);
  const Image smoothed = cross_bilateral_filter(c.view(), f.g, 5, 3.0f, 1.0f, 2);
  for (float v : smoothed.pixels()) EXPECT_NEAR(v, 0.37f, 1e-7f);
  // Values on either side of the step's depth edge never mix with a threshold below it.
  Image split(120, 80, 1);
  for (int y = 0; y < 80; ++y)
    for (int x = 0; x < 120; ++x)
      split(x, y) = f.g.depth(x, y) < f.g.depth(0, 0) - 0.05f ? 1.0f : 0.0f;
  const Image filtered = cross_bilateral_filter(split.view(), f.g, 9, 4.0f, 0.01f, 2);
  EXPECT_EQ(filtered.pixels(), split.pixels());
  EXPECT_NE(testing::invalid_argument_message([&] {
              cross_bilateral_filter(c.view(), f.g, 4, 1.0f, 1.0f);
            }).find("taps"),
            std::string::npos);
}

TEST(VaoPp, AllExtensionsOffIsVao) {
  // The per-sample code is VAO's: with every extension off (spiral set, per-pixel random
  // rotation, no range check, no filter) VAO++ gives VAO's bits.
  SceneFixture f("blocks", 160, 90);
  for (int n : {4, 16}) {
    VaoPpSettings pp;
    pp.radius = 0.5f;
    pp.samples = n;
    pp.adaptive_sampling = false;
    pp.culling = 0;
    pp.range_check = false;
    pp.poisson_samples = false;
    pp.filter = false;
    pp.seed = 3;
    VaoSettings v;
    v.radius = 0.5f;
    v.samples = n;
    v.seed = 3;
    EXPECT_EQ(vao_pp(f.g, pp).pixels(), vao(f.g, v).pixels()) << n;
  }
}

TEST(VaoPp, CullingSkipsOpenAreasAndCarefulStaysClose) {
  SceneFixture f("blocks", 320, 180);
  VaoPpSettings s;
  s.radius = 0.25f;
  s.filter = false;
  s.culling = 0;
  VaoPpStats none, greedy_stats, careful_stats;
  const Image reference = vao_pp(f.g, s, {}, &none);
  EXPECT_EQ(none.culled, 0);
  s.culling = int(VaoPpCulling::Greedy);
  const Image greedy = vao_pp(f.g, s, {}, &greedy_stats);
  s.culling = int(VaoPpCulling::Careful);
  const Image careful = vao_pp(f.g, s, {}, &careful_stats);
  EXPECT_EQ(greedy_stats.culled, careful_stats.culled);
  EXPECT_GT(careful_stats.culled_share(), 0.2);
  EXPECT_LT(careful_stats.culled_share(), 0.98);
  EXPECT_LT(careful_stats.samples, none.samples);
  const double e_greedy = mean_abs_difference(greedy, reference);
  const double e_careful = mean_abs_difference(careful, reference);
  std::printf("blocks 320x180 R 0.25: culled %.1f %%, mean |dA| greedy %.5f careful %.5f\n",
              100 * careful_stats.culled_share(), e_greedy, e_careful);
  EXPECT_LT(e_careful, 0.005);
  EXPECT_LE(e_careful, e_greedy);
  // An open plane is culled entirely.
  SceneFixture plane("plane", 160, 90);
  VaoPpStats plane_stats;
  vao_pp(plane.g, s, {}, &plane_stats);
  EXPECT_EQ(plane_stats.culled, plane_stats.pixels);
}

TEST(VaoPp, AdaptiveSamplingUsesFewerSamplesFarAway) {
  SceneFixture f("ceiling", 320, 180);  // depths from ~0.9 to ~64 across the rows
  VaoPpSettings s;
  s.radius = 1.0f;
  s.samples = 32;
  s.culling = 0;
  VaoPpStats adaptive, fixed;
  vao_pp(f.g, s, {}, &adaptive);
  s.adaptive_sampling = false;
  vao_pp(f.g, s, {}, &fixed);
  EXPECT_DOUBLE_EQ(fixed.mean_samples(), 32.0);
  EXPECT_LT(adaptive.mean_samples(), 32.0);
  EXPECT_GE(adaptive.mean_samples(), 2.0);
}

// A G-buffer of `name` with a constant colour and emission.
struct Coloured {
  SceneFixture f;
  Image color, emission;
  GBuffer g;
  Coloured(const char* name, float r, float gr, float b, float emit = 0.0f)
      : f(name, 160, 90), color(160, 90, 3), emission(160, 90, 3, emit), g(f.g) {
    for (int y = 0; y < 90; ++y)
      for (int x = 0; x < 160; ++x) color(x, y, 0) = r, color(x, y, 1) = gr, color(x, y, 2) = b;
    g.color = color.view();
    g.emission = emission.view();
  }
};

TEST(VaoPp, ColourBleedingIsRgbAndWhiteMeansNoBleeding) {
  VaoPpSettings s;
  s.radius = 0.5f;
  const Coloured white("crease", 1, 1, 1);
  const Image ao = vao_pp(white.g, s);
  s.color_bleeding = true;
  const Image rgb = vao_pp(white.g, s);
  ASSERT_EQ(rgb.channels(), 3);
  for (int y = 0; y < 90; ++y)
    for (int x = 0; x < 160; ++x)
      for (int c = 0; c < 3; ++c) ASSERT_EQ(rgb(x, y, c), ao(x, y)) << x << " " << y;
  // A red scene bleeds red: R >= G everywhere, and strictly somewhere.
  const Coloured red("crease", 0.9f, 0.1f, 0.1f);
  for (int step : {1, 2, 4}) {
    s.bleeding_sample_step = step;
    const Image out = vao_pp(red.g, s);
    bool redder = false;
    for (int y = 0; y < 90; ++y)
      for (int x = 0; x < 160; ++x) {
        EXPECT_GE(out(x, y, 0), out(x, y, 1));
        redder |= out(x, y, 0) > out(x, y, 1) + 0.01f;
      }
    EXPECT_TRUE(redder) << step;
  }
}

TEST(VaoPp, LuminanceSensitivityRemovesAoFromBrightSurfaces) {
  VaoPpSettings s;
  s.radius = 0.5f;
  const Coloured dark("crease", 0.5f, 0.5f, 0.5f);
  const Image plain = vao_pp(dark.g, s);
  s.luminance_sensitivity = true;
  EXPECT_EQ(vao_pp(dark.g, s).pixels(), plain.pixels());    // lum 0.5: below the ramp
  const Coloured bright("crease", 0.5f, 0.5f, 0.5f, 2.0f);  // emission 2: lum 2.5
  const Image lit = vao_pp(bright.g, s);
  EXPECT_EQ(testing::min_valid(lit, bright.g), 1.0f);
  EXPECT_LT(testing::min_valid(plain, dark.g), 0.9f);
  s.luminance_mode = 1;
  EXPECT_EQ(testing::min_valid(vao_pp(bright.g, s), bright.g), 1.0f);
}

// The image is checked by conformance_test; the statistics are VAO++'s own.
TEST(VaoPp, StatsIdenticalAcrossThreadCounts) {
  const Coloured c("blocks", 0.8f, 0.3f, 0.2f, 0.5f);
  for (bool bleeding : {false, true}) {
    VaoPpSettings s;
    s.radius = 0.5f;
    s.color_bleeding = bleeding;
    s.luminance_sensitivity = bleeding;
    s.luminance_threshold = 1.0f;
    VaoPpStats one_stats, seven_stats;
    vao_pp(c.g, s, {1}, &one_stats);
    vao_pp(c.g, s, {7}, &seven_stats);
    EXPECT_EQ(one_stats.pixels, seven_stats.pixels);
    EXPECT_EQ(one_stats.culled, seven_stats.culled);
    EXPECT_EQ(one_stats.samples, seven_stats.samples);
    EXPECT_EQ(one_stats.prepass_pixels, seven_stats.prepass_pixels);
  }
}

// Beyond the ranges of the settings table (conformance_test): the sample sets, odd taps, the
// bleeding steps, and colour only for the settings that read it.
TEST(VaoPp, RejectsBadInputNamingTheSetting) {
  SceneFixture f("plane", 16, 9);
  auto message = [&](const SettingValues& v) {
    return testing::invalid_argument_message([&] { compute("vao_pp", f.g, v); });
  };
  for (const auto& [name, value] : std::vector<std::pair<std::string, double>>{
           {"samples", 12}, {"samples", 3}, {"filter_taps", 4}, {"bleeding_sample_step", 3}})
    EXPECT_EQ(message({{"radius", 1}, {name, value}}).rfind(name, 0), 0u) << name;
  // Colour only when a setting reads it, and the error says which.
  EXPECT_EQ(message({{"radius", 1}}), "");
  EXPECT_NE(message({{"radius", 1}, {"color_bleeding", 1}})
                .find("color is required by vao_pp with color_bleeding"),
            std::string::npos);
  EXPECT_NE(message({{"radius", 1}, {"luminance_sensitivity", 1}}).find("color is required"),
            std::string::npos);
  EXPECT_TRUE(find_method("vao_pp").needs_color);
}

// Beyond the scene's extent a larger R cannot change the occlusion (Vao.LargeRadii...): VAO++
// runs VAO's per-sample code, with and without the range check, which weighs occlusion by
// the distance in units of R.
TEST(VaoPp, LargeRadiiBeyondTheSceneGiveTheSameAo) {
  testing::ConvexRoom room;
  for (bool range_check : {false, true}) {
    VaoPpSettings s;
    s.range_check = range_check;
    testing::expect_large_radii_agree(
        room,
        [&](float radius) {
          s.radius = radius;
          return vao_pp(room.g, s);
        },
        0.999, "range_check = " + std::to_string(range_check));
  }
}

}  // namespace
}  // namespace aolab
