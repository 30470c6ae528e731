// SAO's SIMD path (the estimator of core/horizon/obscurance_simd.cpp shared with Alchemy AO, the
// pyramid and filter of sao_simd.cpp) against its scalar code, the oracle: every setting, on
// analytic scenes and on committed reference scenes; the same bits for any thread count; hard sizes
// and inputs; the pyramid texel for texel; the filter alone. The known-answer tests of sao_test.cpp
// and conformance_test.cpp run the SIMD path too (it is the default).
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/methods/sao/sao.h"
#include "core/methods/sao/sao_blur.h"
#include "core/methods/sao/sao_shared.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::expect_kernels_agree;
using testing::expect_same_bits_for_thread_counts;
using testing::expect_tiny_images_and_hostile_depths_handled;
using testing::kernel_difference;
using testing::ReferenceScene;
using testing::run_kernel;
using testing::SceneFixture;

// The estimator differs from the scalar code by float rounding only, as for Alchemy AO
// (alchemy_simd_test.cpp gives the reasons): the same taps, pyramid levels, texels and source
// pixels (the level is the exponent of h_i, exactly the scalar ilogb), float with v in units
// of r instead of double. The filter is the scalar filter's arithmetic in the same order (a
// fused multiply-add aside), and a weighted mean of values in [0, 1] moves a difference by no
// more than its largest input difference, so the filter does not add to the bounds. Measured
// on every scene and setting below: mean ≤ 3e-7, 99.9th percentile ≤ 1e-4 (`crease` at full
// resolution only). A tap moved across its texel's edge or across |v| = r by an ulp changes
// the raw estimate by at most its share, c·σ/s; the filter then spreads it over its
// neighbours (measured worst 2.3e-4, `crease` at full resolution only). The bounds are
// Alchemy AO's, which the raw estimate reaches.
constexpr double kMeanTolerance = 1e-5;
constexpr double kP999Tolerance = 1e-3;

double worst_tolerance(const SaoSettings& s) {
  const double c = s.falloff == int(ObscuranceFalloff::Smooth) ? 5.0 : 2.0;
  return std::min(1.0, c * s.intensity / s.samples);
}

void expect_kernels_agree(const GBuffer& g, const SaoSettings& s, const std::string& what) {
  testing::expect_kernels_agree(sao, g, s, {kMeanTolerance, kP999Tolerance, worst_tolerance(s)},
                                what);
}

// Every setting away from its default at least once.
std::vector<std::pair<std::string, SaoSettings>> variants(float radius) {
  std::vector<std::pair<std::string, SaoSettings>> out;
  SaoSettings base;
  base.radius = radius;
  out.push_back({"defaults", base});
  auto add = [&](const std::string& name, auto change) {
    SaoSettings s = base;
    change(s);
    out.push_back({name, s});
  };
  add("no filter", [](SaoSettings& s) { s.filter = false; });
  add("samples 5, turns 3", [](SaoSettings& s) { s.samples = 5, s.turns = 3; });
  add("samples 98", [](SaoSettings& s) { s.samples = 98; });
  add("no rotation", [](SaoSettings& s) { s.random_rotation = false; });
  add("smooth falloff", [](SaoSettings& s) { s.falloff = int(ObscuranceFalloff::Smooth); });
  add("intensity 3, contrast 2.5", [](SaoSettings& s) { s.intensity = 3, s.contrast = 2.5f; });
  add("bias 0 (the tangent test decides)", [](SaoSettings& s) { s.bias = 0; });
  add("epsilon 0.2", [](SaoSettings& s) { s.epsilon = 0.2f; });
  add("q' 0, L_max 16", [](SaoSettings& s) { s.log_max_offset = 0, s.max_mip_level = 16; });
  add("q' 1, L_max 2", [](SaoSettings& s) { s.log_max_offset = 1, s.max_mip_level = 2; });
  add("full resolution only", [](SaoSettings& s) { s.max_mip_level = 0; });
  add("reference grid", [](SaoSettings& s) { s.grid = int(SaoGrid::Reference); });
  add("taps at their own pixel",
      [](SaoSettings& s) { s.tap_position = int(SaoTapPosition::Tap), s.log_max_offset = 1; });
  add("normals from depth", [](SaoSettings& s) { s.normals = int(SaoNormals::Depth); });
  add("filter radius 9, stride 1, sigma 0.5",
      [](SaoSettings& s) { s.filter_radius = 9, s.filter_stride = 1, s.filter_sigma = 0.5f; });
  add("filter stride 16", [](SaoSettings& s) { s.filter_stride = 16; });
  add("plain Gaussian filter", [](SaoSettings& s) { s.edge_sharpness = 0; });
  add("edge sharpness 50", [](SaoSettings& s) { s.edge_sharpness = 50; });
  add("seed 7", [](SaoSettings& s) { s.seed = 7; });
  return out;
}

TEST(SaoSimd, MatchesScalarOnAnalyticScenes) {
  for (const char* scene : {"blocks", "wall", "crease", "ceiling", "plane"}) {
    const SceneFixture f(scene, 203, 117);  // widths that are no multiple of any vector length
    for (const auto& [name, s] : variants(scene == std::string("blocks") ? 0.25f : 1.0f))
      expect_kernels_agree(f.g, s, std::string(scene) + ", " + name);
  }
}

TEST(SaoSimd, MatchesScalarAtExtremeRadii) {
  const SceneFixture f("blocks", 97, 61);
  for (float radius : {1e-12f, 1e-4f, 30.0f, 1e20f, 1e30f}) {
    SaoSettings s;
    s.radius = radius;
    expect_kernels_agree(f.g, s, "radius " + std::to_string(radius));
    s.bias = 0;
    s.epsilon = 0;
    s.log_max_offset = 0;
    expect_kernels_agree(f.g, s, "radius " + std::to_string(radius) + ", bias 0, epsilon 0, q' 0");
  }
}

TEST(SaoSimd, MatchesScalarOnReferenceScenes) {
  for (const char* scene : {"room", "street", "grille"}) {
    const ReferenceScene reference(scene);
    const GBuffer& g = reference.g;
    const float radius = reference.radius;  // the scene's own R (its manifest.json)
    for (const auto& [name, s] : variants(radius)) {
      if (name != "defaults" && name != "no filter" && name != "smooth falloff" &&
          name != "bias 0 (the tangent test decides)" && name != "taps at their own pixel")
        continue;
      expect_kernels_agree(g, s, std::string(scene) + ", " + name);
    }
  }
}

TEST(SaoSimd, PyramidIsTheScalarPyramid) {
  const SceneFixture f("blocks", 203, 117);
  const Buffer<float> depth = depth_with_background_as_nan(f.g, 1);
  for (const SaoGrid grid : {SaoGrid::Paper, SaoGrid::Reference}) {
    const auto scalar = sao_z_pyramid(depth, 203, 117, 9, grid, 1);
    const ObscuranceLevels simd = sao_levels_for_simd(depth, 203, 117, 9, grid, true, 2);
    ASSERT_EQ(simd.count, 10);
    for (int m = 1; m < 10; ++m) {
      const SaoZLevel& lv = scalar[std::size_t(m)];
      const std::size_t begin = std::size_t(simd.offset[std::size_t(m)]);
      const std::size_t end = m == 9 ? simd.size() : std::size_t(simd.offset[std::size_t(m) + 1]);
      ASSERT_EQ(end - begin, lv.depth.size());
      for (std::size_t t = 0; t < lv.depth.size(); ++t) {
        const float a = simd.depth(begin + t), b = lv.depth[t];
        EXPECT_TRUE(a == b || (a != a && b != b)) << m << " " << t;
        EXPECT_EQ(simd.source(begin + t), lv.source[t]) << m << " " << t;
      }
    }
  }
}

TEST(SaoSimd, FilterMatchesScalarFilter) {
  const SceneFixture f("blocks", 203, 117);
  const Buffer<float> depth = depth_with_background_as_nan(f.g, 1);
  SaoSettings raw;
  raw.radius = 0.25f;
  raw.filter = false;
  const Image ao = run_kernel(sao, f.g, raw, Kernel::Scalar);
  for (const auto& [radius, stride, edge] :
       std::vector<std::tuple<int, int, float>>{{4, 2, 0.05f}, {1, 1, 0.0f}, {32, 16, 1e-3f}}) {
    SaoBlurParams p;
    p.radius = radius, p.stride = stride, p.edge_depth = edge;
    Image a = ao, b = ao;
    sao_bilateral_filter(a, depth, p, 1, nullptr);
    for (float& v : a.pixels()) v = std::clamp(v, 0.0f, 1.0f);
    sao_bilateral_filter_simd(b, depth, p, 2, nullptr);
    // The same sums in the same order; a fused multiply-add rounds once where the scalar
    // code may round twice: a few ulps of a value in [0, 1].
    constexpr double kFilterTolerance = 1e-6;
    EXPECT_LE(kernel_difference(b, a).worst, kFilterTolerance) << radius << " " << stride;
  }
}

// Every instruction set this machine has, each run alone (the dispatch picks only the best).
TEST(SaoSimd, EveryTargetMatchesScalar) {
  const SceneFixture f("blocks", 203, 117);
  const auto all = variants(0.25f);
  for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    for (const auto& [name, s] : all)
      if (name == "defaults" || name == "no filter" || name == "q' 0, L_max 16" ||
          name == "taps at their own pixel" || name == "filter radius 9, stride 1, sigma 0.5")
        expect_kernels_agree(f.g, s, std::string(hwy::TargetName(target)) + ", " + name);
  }
  hwy::SetSupportedTargetsForTest(0);
}

TEST(SaoSimd, SameBitsForAnyThreadCount) {
  const SceneFixture f("blocks", 203, 117);
  for (const auto& [name, s] : variants(0.25f)) {
    expect_same_bits_for_thread_counts(
        [&](int threads) { return run_kernel(sao, f.g, s, Kernel::Simd, threads); }, name);
  }
}

TEST(SaoSimd, TinyImagesAndHardInputs) {
  // Images smaller than a vector; NaN, infinite, zero and negative depths, which are background:
  // AO 1, and they occlude nothing.
  SaoSettings s;
  s.radius = 0.5f;
  expect_tiny_images_and_hostile_depths_handled(sao, s, worst_tolerance(s));
}

}  // namespace
}  // namespace aolab
