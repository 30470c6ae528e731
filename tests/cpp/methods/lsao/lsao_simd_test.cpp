// LSAO's SIMD kernel (lsao_simd.cpp) against its scalar code, the oracle: every setting, on
// analytic scenes and on committed reference scenes; the same bits for any thread count; hard
// sizes and inputs. The known-answer tests of lsao_test.cpp run the SIMD kernel too (it is the
// default).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/methods/lsao/lsao.h"
#include "core/methods/lsao/lsao_shared.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::expect_kernels_agree;
using testing::expect_same_bits_for_thread_counts;
using testing::expect_tiny_images_and_hostile_depths_handled;
using testing::ReferenceScene;
using testing::run_kernel;
using testing::SceneFixture;

// The SIMD sweep gives the scalar sweep's bits (SweepIsTheScalarSweepBitForBit). The SIMD
// gather picks the same sample per pixel and axis as the scalar one (same stencil, same tie
// rule, the depth and normal tests in the same float operations); it differs in rounding only:
// the pair value w_k O_k + w_k' O_k' and the sums over the K/2 axes are rounded to float where
// the scalar code keeps doubles, a few ulps of A ≤ 1 (measured on every scene and setting
// below: mean ≤ 4e-9, worst 1.2e-7 = 2 ulps of 1).
constexpr double kMeanTolerance = 1e-7;
constexpr double kP999Tolerance = 1e-6;
constexpr double kWorstTolerance = 1e-6;

void expect_kernels_agree(const GBuffer& g, const LsaoSettings& s, const std::string& what) {
  testing::expect_kernels_agree(lsao, g, s, {kMeanTolerance, kP999Tolerance, kWorstTolerance},
                                what);
}

// Every setting away from its default at least once (the presets' layouts among them).
std::vector<std::pair<std::string, LsaoSettings>> variants(float radius) {
  std::vector<std::pair<std::string, LsaoSettings>> out;
  LsaoSettings base;
  base.radius = radius;
  out.push_back({"defaults", base});
  auto add = [&](const std::string& name, auto change) {
    LsaoSettings s = base;
    change(s);
    out.push_back({name, s});
  };
  add("low preset", [](LsaoSettings& s) {
    s.template_size = 1, s.directions = 8, s.template_stride = 2, s.line_spacing = 2.12f;
  });
  add("high preset",
      [](LsaoSettings& s) { s.template_size = 3, s.directions = 24, s.line_spacing = 1.2f; });
  add("ultra preset",
      [](LsaoSettings& s) { s.template_size = 4, s.directions = 32, s.line_spacing = 1.0f; });
  add("uniform K 12 step 2",
      [](LsaoSettings& s) { s.template_size = 0, s.directions = 12, s.step = 2.0f; });
  add("uniform K 7 (no opposites)",
      [](LsaoSettings& s) { s.template_size = 0, s.directions = 7, s.step = 1.5f; });
  add("uniform K 8 dense", [](LsaoSettings& s) {
    s.template_size = 0, s.directions = 8, s.step = 1.0f, s.line_spacing = 1.0f;
  });
  add("interpolate", [](LsaoSettings& s) { s.sampling = int(LsaoSampling::Interpolate); });
  add("uniform interpolate", [](LsaoSettings& s) {
    s.template_size = 0, s.directions = 10, s.step = 1.7f,
    s.sampling = int(LsaoSampling::Interpolate);
  });
  add("real tangent", [](LsaoSettings& s) { s.tangent_strategy = int(LsaoTangent::Real); });
  add("fixed hull tangent",
      [](LsaoSettings& s) { s.tangent_strategy = int(LsaoTangent::FixedHullRealObscurance); });
  add("tangent -0.5", [](LsaoSettings& s) { s.tangent_sin = -0.5f; });
  add("eq. 3", [](LsaoSettings& s) { s.falloff = int(LsaoFalloff::Eq3); });
  add("cutoff", [](LsaoSettings& s) { s.falloff = int(LsaoFalloff::Cutoff); });
  add("depth tolerance 0.02", [](LsaoSettings& s) { s.gather_depth_tolerance = 0.02f; });
  add("depth tolerance 0", [](LsaoSettings& s) { s.gather_depth_tolerance = 0.0f; });
  add("normal-aware", [](LsaoSettings& s) { s.normal_aware_gather = true; });
  add("seed 5", [](LsaoSettings& s) { s.seed = 5; });
  add("hull search 16", [](LsaoSettings& s) { s.hull_search = 16; });
  add("spacing 3.3, stride 3", [](LsaoSettings& s) {
    s.template_size = 1, s.directions = 8, s.template_stride = 3, s.line_spacing = 3.25f;
  });
  add("tuned preset", [](LsaoSettings& s) {
    s.template_size = 1, s.directions = 8, s.template_stride = 3, s.line_spacing = 3.246f;
    s.tangent_strategy = int(LsaoTangent::Real), s.gather_depth_tolerance = 0.0222f;
    s.normal_aware_gather = true, s.hull_search = 16;
  });
  return out;
}

TEST(LsaoSimd, MatchesScalarOnAnalyticScenes) {
  for (const char* scene : {"blocks", "wall", "crease", "step", "plane"}) {
    const SceneFixture f(scene, 203, 117);  // widths that are no multiple of any vector length
    for (const auto& [name, s] : variants(scene == std::string("blocks") ? 0.25f : 1.0f))
      expect_kernels_agree(f.g, s, std::string(scene) + ", " + name);
  }
}

// Same expressions, same order, no fused multiply-add, exact division and square root: the
// vector of lines computes each line's values with the scalar code's operations.
TEST(LsaoSimd, SweepIsTheScalarSweepBitForBit) {
  for (const char* scene : {"blocks", "crease"}) {
    const SceneFixture f(scene, 203, 117);
    for (const auto& [name, s] : variants(scene == std::string("blocks") ? 0.25f : 1.0f)) {
      const LsaoSweep simd = lsao_sweep_simd(f.g, s), scalar = lsao_sweep(f.g, s);
      ASSERT_EQ(simd.buffer.size(), scalar.buffer.size()) << name;
      std::size_t differing = 0;
      for (std::size_t i = 0; i < simd.buffer.size(); ++i) {
        const float a = simd.buffer[i], b = scalar.buffer[i];
        if (!(a == b || (std::isnan(a) && std::isnan(b)))) ++differing;
      }
      EXPECT_EQ(differing, 0u) << scene << ", " << name;
    }
  }
}

TEST(LsaoSimd, MatchesScalarOnReferenceScenes) {
  for (const char* scene : {"room", "street", "grille"}) {
    const ReferenceScene reference(scene);
    const GBuffer& g = reference.g;
    const float radius = reference.radius;  // the scene's own R (its manifest.json)
    for (const auto& [name, s] : variants(radius)) {
      if (name != "defaults" && name != "normal-aware" && name != "low preset") continue;
      expect_kernels_agree(g, s, std::string(scene) + ", " + name);
    }
  }
}

TEST(LsaoSimd, SameBitsForAnyThreadCount) {
  const SceneFixture f("blocks", 203, 117);
  for (const auto& [name, s] : variants(0.25f)) {
    expect_same_bits_for_thread_counts(
        [&](int threads) { return run_kernel(lsao, f.g, s, Kernel::Simd, threads); }, name);
  }
}

TEST(LsaoSimd, TinyImagesAndHardInputs) {
  // Images smaller than a vector; NaN, infinite, zero and negative depths, which are background:
  // AO 1, and they occlude nothing.
  LsaoSettings s;
  s.radius = 0.5f;
  std::vector<std::pair<int, int>> sizes = testing::tiny_image_sizes();
  sizes.insert(sizes.end(), {{1, 40}, {40, 1}});  // one column, one row
  expect_tiny_images_and_hostile_depths_handled(lsao, s, kWorstTolerance, sizes);
}

}  // namespace
}  // namespace aolab
