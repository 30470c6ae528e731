// The visibility bitmask's SIMD kernel (bitmask_simd.cpp) against its scalar code, the oracle:
// every setting, on analytic scenes and on committed reference scenes; the same bits for any thread
// count; hard sizes and inputs. The known-answer tests of bitmask_test.cpp and conformance_test.cpp
// run the SIMD kernel too (it is the default).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/methods/bitmask/bitmask.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::expect_kernels_agree;
using testing::expect_same_bits_for_thread_counts;
using testing::expect_tiny_images_and_hostile_depths_handled;
using testing::ReferenceScene;
using testing::run_kernel;
using testing::SceneFixture;

// The two kernels evaluate the same sample tests; the scalar code places a segment's ends
// among the sector edges by comparing cosines in double, the SIMD kernel by one float atan2
// per end in the frame of the projected normal (and fuses multiplies and adds, and takes
// 1/sqrt from the hardware estimate and a Newton step). They disagree where an end lies
// within a float rounding of a sector edge, and then a whole sector of one slice changes
// (1/N of that slice; `touch` and `cover` rounding, which use the edges; `half` uses the
// centres). On almost every pixel they agree to float ulps; measured over every setting on
// the analytic scenes at 203 × 117 and four settings on the reference scenes: mean ≤ 4e-4
// (ceiling, cosine; ≤ 2e-5 on the reference scenes), 99.9th percentile ≤ 0.06 (ceiling: two
// sectors of 32, cosine-weighted), worst 0.11 (room, cosine). The bounds leave a factor of
// about 2 on each.
constexpr double kMeanTolerance = 1e-3;
constexpr double kP999Tolerance = 0.1;
constexpr double kWorstTolerance = 0.25;
// On `ceiling` without rotation or jitter the vertical slice holds the normal exactly and
// its samples march exactly in it, so samples of the coplanar ceiling that pass the tangent
// test by its rounding margin lie within a float rounding of the hemisphere's edge on most
// pixels, and one sector of that slice flips on about 40 % of them: measured mean 0.012.
constexpr double kAlignedMeanTolerance = 0.03;

void expect_kernels_agree(const GBuffer& g, const BitmaskSettings& s, const std::string& what,
                          double mean_tolerance = kMeanTolerance) {
  testing::expect_kernels_agree(bitmask, g, s, {mean_tolerance, kP999Tolerance, kWorstTolerance},
                                what);
}

// Every setting away from its default at least once.
std::vector<std::pair<std::string, BitmaskSettings>> variants(float radius) {
  std::vector<std::pair<std::string, BitmaskSettings>> out;
  BitmaskSettings base;
  base.radius = radius;
  out.push_back({"defaults", base});
  auto add = [&](const std::string& name, auto change) {
    BitmaskSettings s = base;
    change(s);
    out.push_back({name, s});
  };
  add("slices 5, steps 13", [](BitmaskSettings& s) { s.slices = 5, s.steps = 13; });
  add("slices 1, steps 1", [](BitmaskSettings& s) { s.slices = 1, s.steps = 1; });
  add("steps 40 (three chunks)", [](BitmaskSettings& s) { s.steps = 40; });
  add("no rotation, no jitter", [](BitmaskSettings& s) { s.random_rotation = s.jitter = false; });
  add("sectors 7", [](BitmaskSettings& s) { s.sectors = 7; });
  // q = 2 px: on these small frames every level of the chain is read.
  add("far samples on the MIP chain", [](BitmaskSettings& s) { s.mip_distance = 2.0f; });
  add("sectors 64", [](BitmaskSettings& s) { s.sectors = 64; });
  add("sectors 45, cosine",
      [](BitmaskSettings& s) { s.sectors = 45, s.weighting = int(BitmaskWeighting::Cosine); });
  add("cosine", [](BitmaskSettings& s) { s.weighting = int(BitmaskWeighting::Cosine); });
  add("half", [](BitmaskSettings& s) { s.rounding = int(BitmaskRounding::Half); });
  add("cover", [](BitmaskSettings& s) { s.rounding = int(BitmaskRounding::Cover); });
  add("thickness 0", [](BitmaskSettings& s) { s.thickness = 0.0f; });
  add("thickness 0.1", [](BitmaskSettings& s) { s.thickness = 0.1f; });
  add("unbounded thickness", [](BitmaskSettings& s) { s.thickness = kBitmaskUnboundedThickness; });
  add("sample ray",
      [](BitmaskSettings& s) { s.back_direction = int(BitmaskBackDirection::SampleRay); });
  add("cut", [](BitmaskSettings& s) { s.radius_clip = int(BitmaskRadiusClip::Cut); });
  add("sphere", [](BitmaskSettings& s) { s.radius_clip = int(BitmaskRadiusClip::Sphere); });
  add("EEVEE's: sample ray, sphere, unbounded, cosine", [](BitmaskSettings& s) {
    s.back_direction = int(BitmaskBackDirection::SampleRay);
    s.radius_clip = int(BitmaskRadiusClip::Sphere);
    s.thickness = kBitmaskUnboundedThickness;
    s.weighting = int(BitmaskWeighting::Cosine);
  });
  add("slice normalisation",
      [](BitmaskSettings& s) { s.normalization = int(BitmaskNormalization::Slices); });
  add("slice normalisation, cosine", [](BitmaskSettings& s) {
    s.normalization = int(BitmaskNormalization::Slices);
    s.weighting = int(BitmaskWeighting::Cosine);
  });
  add("seed 7", [](BitmaskSettings& s) { s.seed = 7; });
  return out;
}

TEST(BitmaskSimd, MatchesScalarOnAnalyticScenes) {
  for (const char* scene : {"blocks", "wall", "crease", "ceiling", "plane"}) {
    const SceneFixture f(scene, 203, 117);  // widths that are no multiple of any vector length
    for (const auto& [name, s] : variants(scene == std::string("blocks") ? 0.25f : 1.0f)) {
      const bool aligned = scene == std::string("ceiling") && !s.random_rotation && !s.jitter;
      expect_kernels_agree(f.g, s, std::string(scene) + ", " + name,
                           aligned ? kAlignedMeanTolerance : kMeanTolerance);
    }
  }
}

TEST(BitmaskSimd, OpenPlaneIsExactlyOne) {
  // An open plane raises no horizon: the visible and unoccluded sums are the same bits.
  const SceneFixture f("plane", 203, 117);
  for (const auto& [name, s] : variants(1.0f)) {
    if (s.normalization != int(BitmaskNormalization::Unoccluded)) continue;
    const Image ao =
        run_kernel(bitmask, f.g, s, Kernel::Simd);  // named: a temporary's pixels would dangle
    for (float v : ao.pixels()) ASSERT_EQ(v, 1.0f) << name;
  }
}

TEST(BitmaskSimd, MatchesScalarOnReferenceScenes) {
  for (const char* scene : {"room", "street", "grille"}) {
    const ReferenceScene reference(scene);
    const GBuffer& g = reference.g;
    const float radius = reference.radius;  // the scene's own R (its manifest.json)
    for (const auto& [name, s] : variants(radius)) {
      if (name != "defaults" && name != "cosine" && name != "sphere" &&
          name != "EEVEE's: sample ray, sphere, unbounded, cosine")
        continue;
      expect_kernels_agree(g, s, std::string(scene) + ", " + name);
    }
  }
}

TEST(BitmaskSimd, SameBitsForAnyThreadCount) {
  const SceneFixture f("blocks", 203, 117);
  for (const auto& [name, s] : variants(0.25f)) {
    expect_same_bits_for_thread_counts(
        [&](int threads) { return run_kernel(bitmask, f.g, s, Kernel::Simd, threads); }, name);
  }
}

TEST(BitmaskSimd, TinyImagesAndHardInputs) {
  // Images smaller than a vector; NaN, infinite, zero and negative depths, which are background:
  // AO 1, and they occlude nothing.
  BitmaskSettings s;
  s.radius = 0.5f;
  expect_tiny_images_and_hostile_depths_handled(bitmask, s, kWorstTolerance);
}

}  // namespace
}  // namespace aolab
