// Alchemy AO's SIMD kernel (the estimator of core/horizon/obscurance_simd.cpp, shared with SAO)
// against its scalar code, the oracle: every setting, on analytic scenes and on committed reference
// scenes; the same bits for any thread count; hard sizes and inputs. The known-answer tests of
// alchemy_test.cpp and conformance_test.cpp run the SIMD kernel too (it is the default).
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/methods/alchemy/alchemy.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::expect_kernels_agree;
using testing::expect_same_bits_for_thread_counts;
using testing::expect_tiny_images_and_hostile_depths_handled;
using testing::ReferenceScene;
using testing::run_kernel;
using testing::SceneFixture;

// The kernels place the same taps on the same texels and run the same tests; they differ by
// float rounding: the SIMD kernel works in float with v in units of r where the scalar code
// sums in double, fuses multiplies and adds, and rotates the spiral with Highway's cos and sin
// (a few ulps from the C library's). Almost every pixel agrees to a few float ulps (measured
// on every scene and setting below: mean ≤ 1e-6, 99.9th percentile ≤ 2e-4, the largest with
// bias 0 on `room`, where the sign of v·n for taps on C's own surface is rounding noise that
// only the tangent-plane test's tolerance removes, and near that tolerance float and double
// decide differently). On a few pixels in 10^6 an ulp moves a tap across the edge of the texel
// it snaps to, or across |v| = r where the Alchemy falloff cuts it off, which changes that
// tap's term: by at most its whole share of A, which for a tap at |v| ≈ r (the cut) is
// (c·σ/s)·(v·n − b)·r/(r² + ε·r²) ≤ c·σ/s, and for a snapped tap the difference of two
// neighbouring texels' terms (measured worst 0.058 on `street`, s = 12, where c·σ/s = 0.17).
constexpr double kMeanTolerance = 1e-5;
constexpr double kP999Tolerance = 1e-3;

double worst_tolerance(const AlchemySettings& s) {
  const double c = s.falloff == int(ObscuranceFalloff::Smooth) ? 5.0 : 2.0;
  return std::min(1.0, c * s.intensity / s.samples);
}

void expect_kernels_agree(const GBuffer& g, const AlchemySettings& s, const std::string& what) {
  testing::expect_kernels_agree(alchemy, g, s, {kMeanTolerance, kP999Tolerance, worst_tolerance(s)},
                                what);
}

// Every setting away from its default at least once.
std::vector<std::pair<std::string, AlchemySettings>> variants(float radius) {
  std::vector<std::pair<std::string, AlchemySettings>> out;
  AlchemySettings base;
  base.radius = radius;
  out.push_back({"defaults", base});
  auto add = [&](const std::string& name, auto change) {
    AlchemySettings s = base;
    change(s);
    out.push_back({name, s});
  };
  add("samples 5, turns 3", [](AlchemySettings& s) { s.samples = 5, s.turns = 3; });
  add("samples 98", [](AlchemySettings& s) { s.samples = 98; });
  add("samples 1", [](AlchemySettings& s) { s.samples = 1; });
  add("no rotation", [](AlchemySettings& s) { s.random_rotation = false; });
  add("smooth falloff", [](AlchemySettings& s) { s.falloff = int(ObscuranceFalloff::Smooth); });
  add("intensity 3, contrast 2.5", [](AlchemySettings& s) { s.intensity = 3, s.contrast = 2.5f; });
  add("contrast 0.4", [](AlchemySettings& s) { s.contrast = 0.4f; });
  add("bias 0 (the tangent test decides)", [](AlchemySettings& s) { s.bias = 0; });
  add("bias 0.05", [](AlchemySettings& s) { s.bias = 0.05f; });
  add("epsilon 0", [](AlchemySettings& s) { s.epsilon = 0; });
  add("epsilon 0.2", [](AlchemySettings& s) { s.epsilon = 0.2f; });
  add("seed 7", [](AlchemySettings& s) { s.seed = 7; });
  return out;
}

TEST(AlchemySimd, MatchesScalarOnAnalyticScenes) {
  for (const char* scene : {"blocks", "wall", "crease", "ceiling", "plane"}) {
    const SceneFixture f(scene, 203, 117);  // widths that are no multiple of any vector length
    for (const auto& [name, s] : variants(scene == std::string("blocks") ? 0.25f : 1.0f))
      expect_kernels_agree(f.g, s, std::string(scene) + ", " + name);
  }
}

TEST(AlchemySimd, MatchesScalarAtExtremeRadii) {
  const SceneFixture f("blocks", 97, 61);
  for (float radius : {1e-12f, 1e-4f, 30.0f, 1e20f, 1e30f}) {
    AlchemySettings s;
    s.radius = radius;
    expect_kernels_agree(f.g, s, "radius " + std::to_string(radius));
    s.bias = 0;
    s.epsilon = 0;
    expect_kernels_agree(f.g, s, "radius " + std::to_string(radius) + ", bias 0, epsilon 0");
  }
}

TEST(AlchemySimd, MatchesScalarOnReferenceScenes) {
  for (const char* scene : {"room", "street", "grille"}) {
    const ReferenceScene reference(scene);
    const GBuffer& g = reference.g;
    const float radius = reference.radius;  // the scene's own R (its manifest.json)
    for (const auto& [name, s] : variants(radius)) {
      if (name != "defaults" && name != "smooth falloff" &&
          name != "bias 0 (the tangent test decides)")
        continue;
      expect_kernels_agree(g, s, std::string(scene) + ", " + name);
    }
  }
}

// Every instruction set this machine has (SSE4, AVX2, AVX-512 ...), each run alone: the
// dispatch picks only the best one, so the others would go untested.
TEST(AlchemySimd, EveryTargetMatchesScalar) {
  const SceneFixture f("blocks", 203, 117);
  const auto all = variants(0.25f);
  for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    for (const auto& [name, s] : all)
      if (name == "defaults" || name == "smooth falloff" || name == "contrast 0.4")
        expect_kernels_agree(f.g, s, std::string(hwy::TargetName(target)) + ", " + name);
  }
  hwy::SetSupportedTargetsForTest(0);
}

TEST(AlchemySimd, SameBitsForAnyThreadCount) {
  const SceneFixture f("blocks", 203, 117);
  for (const auto& [name, s] : variants(0.25f)) {
    expect_same_bits_for_thread_counts(
        [&](int threads) { return run_kernel(alchemy, f.g, s, Kernel::Simd, threads); }, name);
  }
}

TEST(AlchemySimd, TinyImagesAndHardInputs) {
  // Images smaller than a vector; NaN, infinite, zero and negative depths, which are background:
  // AO 1, and they occlude nothing.
  AlchemySettings s;
  s.radius = 0.5f;
  expect_tiny_images_and_hostile_depths_handled(alchemy, s, worst_tolerance(s));
}

}  // namespace
}  // namespace aolab
