// Crytek SSAO's SIMD kernel (crytek_ssao_simd.cpp) against its scalar code, the oracle: every
// setting, on analytic scenes and on committed reference scenes; the same bits for any thread
// count; hard sizes, background of every kind, a depth view with a row stride. The
// known-answer tests of crytek_ssao_test.cpp and conformance_test.cpp run the SIMD kernel
// too (it is the default).
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "core/methods/crytek_ssao/crytek_ssao.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::expect_in_unit_interval;
using testing::expect_kernels_agree;
using testing::expect_same_bits_for_thread_counts;
using testing::HostileDepths;
using testing::kernel_difference;
using testing::KernelTolerance;
using testing::ReferenceScene;
using testing::run_kernel;
using testing::SceneFixture;

// The two kernels take the same points and, with the tiled reflection or none, the same
// offsets and point depths to the bit. They differ where the SIMD kernel projects a point
// with one reciprocal and fused multiply-adds (a few ulps of its pixel coordinates), weighs
// the smooth range check by Δ·(1/R) instead of Δ/R (an ulp of a weight), and, with the
// per-pixel reflection, draws the reflection vector with Highway's sin/cos (a few ulps of
// every offset).
//
// Almost every pixel then agrees to a few ulps of its weights: the 99.9th percentile
// (measured ≤ 1.2e-7 over every scene and setting below).
constexpr double kUlpTolerance = 1e-6;

// A point's outcome changes only where those ulps move it across a texel edge (into a texel of
// another depth) or, with the hemisphere, flip an offset lying within ulps of the tangent
// plane: on a few pixels in 10^4 (measured ≤ 1.3e-4 of the pixels, on `street`), well under
// the 1e-3 that would move the 99.9th percentile.
constexpr double kChangedPixelFraction = 1e-3;

// One changed point moves A by at most its weight 1/N, doubled by the rescaled output.
double point_share(const CrytekSsaoSettings& s) {
  return (s.output == int(CrytekSsaoOutput::Rescaled) ? 2.0 : 1.0) / s.samples;
}

// The mean: changed pixels times a point's share, plus the ulps.
double mean_tolerance(const CrytekSsaoSettings& s) {
  return kChangedPixelFraction * point_share(s) + kUlpTolerance;
}

// The worst pixel: measured never more than one changed point in a pixel; two are allowed, as
// two such edge cases can meet in one pixel.
double worst_tolerance(const CrytekSsaoSettings& s) { return 2.0 * point_share(s); }

void expect_kernels_agree(const GBuffer& g, const CrytekSsaoSettings& s, const std::string& what) {
  testing::expect_kernels_agree(crytek_ssao, g, s,
                                {mean_tolerance(s), kUlpTolerance, worst_tolerance(s)}, what);
}

// Every setting away from its default at least once, and the combinations that take other
// paths of the kernel (per-pixel reflection with the hemisphere).
std::vector<std::pair<std::string, CrytekSsaoSettings>> variants(float radius) {
  std::vector<std::pair<std::string, CrytekSsaoSettings>> out;
  CrytekSsaoSettings base;
  base.radius = radius;
  out.push_back({"defaults", base});
  auto add = [&](const std::string& name, auto change) {
    CrytekSsaoSettings s = base;
    change(s);
    out.push_back({name, s});
  };
  add("7 points", [](CrytekSsaoSettings& s) { s.samples = 7; });
  add("64 points", [](CrytekSsaoSettings& s) { s.samples = 64; });
  add("uniform",
      [](CrytekSsaoSettings& s) { s.distribution = int(CrytekSsaoDistribution::Uniform); });
  add("per-pixel reflection",
      [](CrytekSsaoSettings& s) { s.rotation = int(CrytekSsaoRotation::PerPixel); });
  add("no reflection", [](CrytekSsaoSettings& s) { s.rotation = int(CrytekSsaoRotation::None); });
  add("hard range check",
      [](CrytekSsaoSettings& s) { s.range_check = int(CrytekSsaoRangeCheck::Hard); });
  add("no range check",
      [](CrytekSsaoSettings& s) { s.range_check = int(CrytekSsaoRangeCheck::Off); });
  add("published", [](CrytekSsaoSettings& s) { s.output = int(CrytekSsaoOutput::Published); });
  add("hemisphere", [](CrytekSsaoSettings& s) { s.hemisphere = true; });
  add("hemisphere, per-pixel reflection", [](CrytekSsaoSettings& s) {
    s.hemisphere = true, s.rotation = int(CrytekSsaoRotation::PerPixel);
  });
  add("hemisphere, no reflection, no range check", [](CrytekSsaoSettings& s) {
    s.hemisphere = true, s.rotation = int(CrytekSsaoRotation::None),
    s.range_check = int(CrytekSsaoRangeCheck::Off);
  });
  add("seed 7", [](CrytekSsaoSettings& s) { s.seed = 7; });
  // Spheres that reach behind the camera plane (points with depth ≤ 0) and off the image.
  add("radius ×40", [](CrytekSsaoSettings& s) { s.radius *= 40.0f; });
  return out;
}

TEST(CrytekSsaoSimd, MatchesScalarOnAnalyticScenes) {
  for (const char* scene : {"blocks", "wall", "crease", "ceiling", "plane"}) {
    const SceneFixture f(scene, 203, 117);  // widths that are no multiple of any vector length
    for (const auto& [name, s] : variants(scene == std::string("blocks") ? 0.25f : 1.0f))
      expect_kernels_agree(f.g, s, std::string(scene) + ", " + name);
  }
}

TEST(CrytekSsaoSimd, MatchesScalarOnReferenceScenes) {
  for (const char* scene : {"room", "street", "grille"}) {
    const ReferenceScene reference(scene);
    const GBuffer& g = reference.g;
    const float radius = reference.radius;  // the scene's own R (its manifest.json)
    for (const auto& [name, s] : variants(radius)) {
      if (name != "defaults" && name != "per-pixel reflection" && name != "hemisphere" &&
          name != "published")
        continue;
      expect_kernels_agree(g, s, std::string(scene) + ", " + name);
    }
  }
}

TEST(CrytekSsaoSimd, SameBitsForAnyThreadCount) {
  const SceneFixture f("blocks", 203, 117);
  for (const auto& [name, s] : variants(0.25f)) {
    expect_same_bits_for_thread_counts(
        [&](int threads) { return run_kernel(crytek_ssao, f.g, s, Kernel::Simd, threads); }, name);
  }
}

// Every instruction set the kernel was compiled for that this machine runs (AVX-512, AVX2,
// SSE4, ... and Highway's 1-lane scalar target, whose vectors are too short for the tile's
// period and take the per-lane path), each against the scalar code.
TEST(CrytekSsaoSimd, EveryCompiledTargetMatchesScalar) {
  const SceneFixture f("blocks", 37, 21);
  const std::vector<std::int64_t> targets = hwy::SupportedAndGeneratedTargets();
  EXPECT_GE(targets.size(), 2u);
  for (const std::int64_t target : targets) {
    hwy::SetSupportedTargetsForTest(target);
    for (const auto& [name, s] : variants(0.5f))
      expect_kernels_agree(f.g, s, std::string(hwy::TargetName(target)) + ", " + name);
  }
  hwy::SetSupportedTargetsForTest(0);  // back to every target the machine has
}

TEST(CrytekSsaoSimd, TinyImages) {
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{{1, 1}, {7, 3}, {13, 5}, {17, 2}}) {
    SceneFixture f("blocks", w, h);
    for (const auto& [name, s] : variants(0.5f)) {
      const Image simd = run_kernel(crytek_ssao, f.g, s, Kernel::Simd);
      const std::string what = std::to_string(w) + "x" + std::to_string(h) + ", " + name;
      expect_kernels_agree(simd, run_kernel(crytek_ssao, f.g, s, Kernel::Scalar),
                           KernelTolerance::worst_only(worst_tolerance(s)), what);
      expect_in_unit_interval(simd, what);
    }
  }
}

// The kernel reads the G-buffer's depth in place and tests each read for background: NaN,
// infinite, zero, negative depths and depths at or beyond background_depth are background
// (AO 1) and occlude nothing, as the scalar code's NaN copy makes them.
TEST(CrytekSsaoSimd, BackgroundOfEveryKind) {
  const int w = 41, h = 23;
  SceneFixture f("blocks", w, h);
  HostileDepths hostile(f.g);
  std::vector<float> bad = testing::hostile_depth_values();
  bad.push_back(-0.0f);
  bad.push_back(1e30f);
  for (int i = 0; i < int(bad.size()); ++i)
    for (int x = i % 3; x < w; x += 3) hostile.set(x, 2 + 3 * i, bad[i]);
  GBuffer& g = hostile.g;
  g.background_depth = 1e20f;  // 1e30 is background
  for (const auto& [name, s] : variants(0.5f)) {
    const Image simd = run_kernel(crytek_ssao, g, s, Kernel::Simd);
    expect_kernels_agree(
        simd, run_kernel(crytek_ssao, g, s, Kernel::Scalar),
        {mean_tolerance(s), std::numeric_limits<double>::infinity(), worst_tolerance(s)}, name);
    hostile.expect_ao_one(simd, name);
  }
  // A finite background_depth below some of the scene: those pixels become background.
  GBuffer near = f.g;
  float lowest = std::numeric_limits<float>::infinity(), highest = 0.0f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      lowest = std::min(lowest, f.g.depth(x, y)), highest = std::max(highest, f.g.depth(x, y));
  near.background_depth = 0.5f * (lowest + highest);
  for (const auto& [name, s] : variants(0.5f)) {
    expect_kernels_agree(crytek_ssao, near, s, KernelTolerance::worst_only(worst_tolerance(s)),
                         "finite background, " + name);
  }
}

// A depth view whose rows are longer than the image (row_stride > width): the kernel's
// gathers index rows by the stride.
TEST(CrytekSsaoSimd, DepthViewWithARowStride) {
  const int w = 75, h = 43, pad = 9;
  SceneFixture f("blocks", w, h);
  Image wide(w + pad, h, 1, std::numeric_limits<float>::quiet_NaN());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) wide(x, y) = f.g.depth(x, y);
  GBuffer g = f.g;
  g.depth = ConstImageView(std::as_const(wide).data(), w, h, 1, w + pad);
  CrytekSsaoSettings s;
  s.radius = 0.5f;
  const Image strided = run_kernel(crytek_ssao, g, s, Kernel::Simd);
  EXPECT_EQ(strided.pixels(), run_kernel(crytek_ssao, f.g, s, Kernel::Simd).pixels());
  const auto k = kernel_difference(strided, run_kernel(crytek_ssao, g, s, Kernel::Scalar));
  EXPECT_LE(k.worst, worst_tolerance(s));
}

}  // namespace
}  // namespace aolab
