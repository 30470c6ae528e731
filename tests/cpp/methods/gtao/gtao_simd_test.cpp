// GTAO's SIMD kernel (gtao_simd.cpp) against its scalar code, the oracle: every setting, on
// analytic scenes and on committed reference scenes; the same bits for any thread count; hard
// sizes and inputs. The known-answer tests of gtao_test.cpp and conformance_test.cpp run the
// SIMD kernel too (it is the default).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/methods/gtao/gtao.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::expect_kernels_agree;
using testing::expect_same_bits_for_thread_counts;
using testing::expect_tiny_images_and_hostile_depths_handled;
using testing::ReferenceScene;
using testing::run_kernel;
using testing::SceneFixture;

// The two kernels evaluate the same expressions, the scalar code eq. 7 in double and the SIMD
// kernel in float (with acos from Highway and cos(2h − n) by the double-angle formulas), and
// the SIMD kernel fuses multiplies and adds and takes 1/sqrt from the hardware estimate and a
// Newton step. Almost every pixel agrees to a few float ulps of AO (measured below: on the
// analytic scenes mean ≤ 5e-8, 99.9th percentile ≤ 2e-7, worst ≤ 5e-7; on the reference
// scenes mean ≤ 4e-7, 99.9th percentile ≤ 2e-6). On a few pixels in 10^5 of the reference
// scenes such an ulp moves a sample across a texel edge where it snaps, which changes one
// side of one slice: measured worst 0.11 (room, thickness 0.3). The bounds leave a factor
// of 25 on the mean, 50 on the percentile and 2 on the worst.
constexpr double kMeanTolerance = 1e-5;
constexpr double kP999Tolerance = 1e-4;
constexpr double kWorstTolerance = 0.25;

void expect_kernels_agree(const GBuffer& g, const GtaoSettings& s, const std::string& what) {
  testing::expect_kernels_agree(gtao, g, s, {kMeanTolerance, kP999Tolerance, kWorstTolerance},
                                what);
}

// Every setting away from its default at least once.
std::vector<std::pair<std::string, GtaoSettings>> variants(float radius) {
  std::vector<std::pair<std::string, GtaoSettings>> out;
  GtaoSettings base;
  base.radius = radius;
  out.push_back({"defaults", base});
  auto add = [&](const std::string& name, auto change) {
    GtaoSettings s = base;
    change(s);
    out.push_back({name, s});
  };
  add("slices 5, steps 13", [](GtaoSettings& s) { s.slices = 5, s.steps = 13; });
  add("slices 1, steps 1", [](GtaoSettings& s) { s.slices = 1, s.steps = 1; });
  add("steps 40 (three chunks)", [](GtaoSettings& s) { s.steps = 40; });
  add("no rotation, no jitter", [](GtaoSettings& s) { s.random_rotation = s.jitter = false; });
  add("falloff 0.615", [](GtaoSettings& s) { s.falloff = 0.615f; });
  add("falloff 1", [](GtaoSettings& s) { s.falloff = 1.0f; });
  add("thickness 0.3", [](GtaoSettings& s) { s.thickness = 0.3f; });
  add("thickness 1, falloff 0.5", [](GtaoSettings& s) { s.thickness = 1.0f, s.falloff = 0.5f; });
  add("slice normalisation",
      [](GtaoSettings& s) { s.normalization = int(GtaoNormalization::Slices); });
  add("multi-bounce", [](GtaoSettings& s) { s.multi_bounce = true; });
  add("multi-bounce, albedo 0.2", [](GtaoSettings& s) { s.multi_bounce = true, s.albedo = 0.2f; });
  add("seed 7", [](GtaoSettings& s) { s.seed = 7; });
  return out;
}

TEST(GtaoSimd, MatchesScalarOnAnalyticScenes) {
  for (const char* scene : {"blocks", "wall", "crease", "ceiling", "plane"}) {
    const SceneFixture f(scene, 203, 117);  // widths that are no multiple of any vector length
    for (const auto& [name, s] : variants(scene == std::string("blocks") ? 0.25f : 1.0f))
      expect_kernels_agree(f.g, s, std::string(scene) + ", " + name);
  }
}

TEST(GtaoSimd, OpenPlaneIsExactlyOne) {
  // An open plane raises no horizon: the visible and unoccluded sums are the same bits.
  const SceneFixture f("plane", 203, 117);
  for (const auto& [name, s] : variants(1.0f)) {
    if (s.normalization != int(GtaoNormalization::Unoccluded)) continue;
    const Image ao =
        run_kernel(gtao, f.g, s, Kernel::Simd);  // named: a temporary's pixels would dangle
    for (float v : ao.pixels()) ASSERT_EQ(v, 1.0f) << name;
  }
}

TEST(GtaoSimd, MatchesScalarOnReferenceScenes) {
  for (const char* scene : {"room", "street", "grille"}) {
    const ReferenceScene reference(scene);
    const GBuffer& g = reference.g;
    const float radius = reference.radius;  // the scene's own R (its manifest.json)
    for (const auto& [name, s] : variants(radius)) {
      if (name != "defaults" && name != "falloff 0.615" && name != "thickness 0.3" &&
          name != "slice normalisation")
        continue;
      expect_kernels_agree(g, s, std::string(scene) + ", " + name);
    }
  }
}

TEST(GtaoSimd, SameBitsForAnyThreadCount) {
  const SceneFixture f("blocks", 203, 117);
  for (const auto& [name, s] : variants(0.25f)) {
    expect_same_bits_for_thread_counts(
        [&](int threads) { return run_kernel(gtao, f.g, s, Kernel::Simd, threads); }, name);
  }
}

TEST(GtaoSimd, TinyImagesAndHardInputs) {
  // Images smaller than a vector; NaN, infinite, zero and negative depths, which are background:
  // AO 1, and they occlude nothing.
  GtaoSettings s;
  s.radius = 0.5f;
  expect_tiny_images_and_hostile_depths_handled(gtao, s, kWorstTolerance);
}

}  // namespace
}  // namespace aolab
