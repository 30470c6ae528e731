// The SIMD kernel of VAO and VAO++ (core/volumetric/pipes_simd.cpp, bilateral_simd.cpp) against
// their scalar code, the oracle: every setting, on analytic scenes and on committed reference
// scenes, at the extreme radii; the same bits for any thread count; hard sizes and inputs. The
// known-answer tests of vao_test.cpp, vao_pp_test.cpp and conformance_test.cpp run the SIMD
// kernel too (it is the default).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/methods/vao/vao.h"
#include "core/methods/vao_pp/bilateral.h"
#include "core/methods/vao_pp/vao_pp.h"
#include "core/methods/vao_pp/vao_pp_shared.h"
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

// The kernels evaluate the same cases on the same samples; the SIMD kernel works in float
// where the scalar code works in double (the sphere scaled to O(1), the roots formed without
// cancellation, the intersection's discriminant as a r² − |v × C|² where b² − a c cancels,
// the pipe on P's own texel in closed form), projects a sample by one multiply-add, rotates
// the sample sets with Highway's sin/cos (VAO's random rotation) or float products (VAO++'s
// tiles) and fuses multiplies with adds. Almost every pixel agrees to a few ulps (measured
// over every scene and setting below: mean ≤ 6.2e-7, 99.9th percentile ≤ 1.3e-5). A few
// pixels in 10^5 differ by a sample: an ulp moves a sample across a texel edge (another
// surface depth), or a surface within a few ulps of a pipe's far end across the case test's
// rounding tolerance (case A against B). Such a pixel changes by that sample's share of F:
// its pipe's length over the sum of the n pipes' (measured worst 0.087 at 16 samples, on
// `grille`); the bound allows a pipe four times the mean length.
constexpr double kMeanTolerance = 5e-6;
constexpr double kP999Tolerance = 1e-4;
double worst_tolerance(int samples) { return std::min(1.0, 4.0 / samples); }

Image run(const GBuffer& g, const VaoSettings& s, Kernel kernel, int threads = 0) {
  return run_kernel(vao, g, s, kernel, threads);
}

Image run(const GBuffer& g, const VaoPpSettings& s, Kernel kernel, int threads = 0,
          VaoPpStats* stats = nullptr) {
  RunOptions options;
  options.kernel = kernel;
  options.threads = threads;
  return vao_pp(g, s, options, stats);
}

template <class Settings>
void expect_kernels_agree(const GBuffer& g, const Settings& s, const std::string& what) {
  testing::expect_kernels_agree(run(g, s, Kernel::Simd), run(g, s, Kernel::Scalar),
                                {kMeanTolerance, kP999Tolerance, worst_tolerance(s.samples)}, what);
}

// Every VAO setting away from its default at least once.
std::vector<std::pair<std::string, VaoSettings>> vao_variants(float radius) {
  std::vector<std::pair<std::string, VaoSettings>> out;
  VaoSettings base;
  base.radius = radius;
  out.push_back({"vao defaults", base});
  auto add = [&](const std::string& name, auto change) {
    VaoSettings s = base;
    change(s);
    out.push_back({name, s});
  };
  add("vao 8 samples (medium)", [](VaoSettings& s) { s.samples = 8; });
  add("vao 1 sample", [](VaoSettings& s) { s.samples = 1; });
  add("vao 64 samples", [](VaoSettings& s) { s.samples = 64; });
  add("vao no rotation", [](VaoSettings& s) { s.random_rotation = false; });
  add("vao axis pipes (eq. 2)", [](VaoSettings& s) { s.view_ray_pipes = false; });
  add("vao seed 7", [](VaoSettings& s) { s.seed = 7; });
  return out;
}

// Every VAO++ setting away from its default at least once (colour ones in MatchesScalarWith
// Colour).
std::vector<std::pair<std::string, VaoPpSettings>> vao_pp_variants(float radius) {
  std::vector<std::pair<std::string, VaoPpSettings>> out;
  VaoPpSettings base;
  base.radius = radius;
  out.push_back({"vao_pp defaults", base});
  auto add = [&](const std::string& name, auto change) {
    VaoPpSettings s = base;
    change(s);
    out.push_back({name, s});
  };
  add("vao_pp 8 samples (medium)", [](VaoPpSettings& s) { s.samples = 8; });
  add("vao_pp 2 samples", [](VaoPpSettings& s) { s.samples = 2; });
  add("vao_pp 32 samples", [](VaoPpSettings& s) { s.samples = 32; });
  add("vao_pp axis pipes", [](VaoPpSettings& s) { s.view_ray_pipes = false; });
  add("vao_pp no adaptive", [](VaoPpSettings& s) { s.adaptive_sampling = false; });
  add("vao_pp min diameter 0.05", [](VaoPpSettings& s) { s.adaptive_min_diameter = 0.05f; });
  add("vao_pp culling off", [](VaoPpSettings& s) { s.culling = int(VaoPpCulling::Off); });
  add("vao_pp greedy culling", [](VaoPpSettings& s) { s.culling = int(VaoPpCulling::Greedy); });
  add("vao_pp cull threshold 0.9", [](VaoPpSettings& s) { s.cull_threshold = 0.9f; });
  add("vao_pp no range check", [](VaoPpSettings& s) { s.range_check = false; });
  add("vao_pp spiral", [](VaoPpSettings& s) { s.poisson_samples = false; });
  add("vao_pp no filter", [](VaoPpSettings& s) { s.filter = false; });
  add("vao_pp filter 7 taps, sigma 1.5",
      [](VaoPpSettings& s) { s.filter_taps = 7, s.filter_sigma = 1.5f; });
  add("vao_pp seed 7", [](VaoPpSettings& s) { s.seed = 7; });
  add("vao_pp spiral, seed 7", [](VaoPpSettings& s) { s.poisson_samples = false, s.seed = 7; });
  return out;
}

TEST(VaoSimd, MatchesScalarOnAnalyticScenes) {
  for (const char* scene : {"blocks", "wall", "crease", "ceiling", "plane"}) {
    const SceneFixture f(scene, 203, 117);  // widths that are no multiple of any vector length
    const float radius = scene == std::string("blocks") ? 0.25f : 1.0f;
    for (const auto& [name, s] : vao_variants(radius))
      expect_kernels_agree(f.g, s, std::string(scene) + ", " + name);
    for (const auto& [name, s] : vao_pp_variants(radius))
      expect_kernels_agree(f.g, s, std::string(scene) + ", " + name);
  }
}

// The radii the scalar code went to double for: the sphere 1e-12 and 1e30 across (a huge
// sphere contains the camera; its far ends lie on the tangent plane).
TEST(VaoSimd, MatchesScalarAtExtremeRadii) {
  for (const char* scene : {"blocks", "crease", "plane"})
    for (float radius : {1e-12f, 1e-4f, 100.0f, 1e8f, 1e30f}) {
      const SceneFixture f(scene, 97, 61);
      const std::string what = std::string(scene) + ", R " + std::to_string(radius);
      VaoSettings s;
      s.radius = radius;
      expect_kernels_agree(f.g, s, what + ", vao");
      s.view_ray_pipes = false;
      expect_kernels_agree(f.g, s, what + ", vao axis pipes");
      VaoPpSettings p;
      p.radius = radius;
      expect_kernels_agree(f.g, p, what + ", vao_pp");
    }
}

// A scene whose colour changes from texel to texel, so that every sample's bleeding term
// differs.
struct Striped {
  SceneFixture f;
  Image color, emission;
  GBuffer g;
  Striped(const char* name, int w, int h)
      : f(name, w, h), color(w, h, 3), emission(w, h, 3), g(f.g) {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        color(x, y, 0) = float((x * 7) % 11) / 10.0f;
        color(x, y, 1) = float((y * 5) % 7) / 6.0f;
        color(x, y, 2) = (x + y) % 2 ? 0.2f : 0.9f;
        for (int c = 0; c < 3; ++c) emission(x, y, c) = (x / 13 + y / 9) % 3 == 0 ? 1.5f : 0.0f;
      }
    g.color = color.view();
    g.emission = emission.view();
  }
};

TEST(VaoSimd, MatchesScalarWithColour) {
  for (const char* scene : {"blocks", "crease"}) {
    const Striped st(scene, 203, 117);
    const float radius = scene == std::string("blocks") ? 0.25f : 1.0f;
    for (int step : {1, 2, 4}) {
      VaoPpSettings s;
      s.radius = radius;
      s.color_bleeding = true;
      s.bleeding_sample_step = step;
      expect_kernels_agree(st.g, s, std::string(scene) + ", bleeding step " + std::to_string(step));
    }
    VaoPpSettings s;
    s.radius = radius;
    s.luminance_sensitivity = true;
    expect_kernels_agree(st.g, s, std::string(scene) + ", luminance");
    s.luminance_mode = 1;
    s.luminance_threshold = 0.5f;
    expect_kernels_agree(st.g, s, std::string(scene) + ", luminance value");
  }
}

TEST(VaoSimd, MatchesScalarOnReferenceScenes) {
  for (const char* scene : {"room", "street", "grille"}) {
    const ReferenceScene reference(scene);
    const GBuffer& g = reference.g;
    const float radius = reference.radius;  // the scene's own R (its manifest.json)
    for (const auto& [name, s] : vao_variants(radius))
      if (name == "vao defaults" || name == "vao axis pipes (eq. 2)")
        expect_kernels_agree(g, s, std::string(scene) + ", " + name);
    for (const auto& [name, s] : vao_pp_variants(radius))
      if (name == "vao_pp defaults" || name == "vao_pp spiral" || name == "vao_pp culling off")
        expect_kernels_agree(g, s, std::string(scene) + ", " + name);
    if (g.has_color()) {
      VaoPpSettings s;
      s.radius = radius;
      s.color_bleeding = true;
      expect_kernels_agree(g, s, std::string(scene) + ", vao_pp colour bleeding");
    }
  }
}

// §4.2's decisions are the scalar code's bit for bit (the same bilinear fetches); §4.1's
// counts are made in float, which can round a disc whose area is within an ulp of a doubling
// to the other side (measured: none on these scenes).
TEST(VaoSimd, CullingAndAdaptiveCountsMatchTheScalarCode) {
  for (const char* scene : {"blocks", "crease", "wall"}) {
    const SceneFixture f(scene, 203, 117);
    for (int culling : {1, 2}) {
      VaoPpSettings s;
      s.radius = scene == std::string("blocks") ? 0.25f : 1.0f;
      s.culling = culling;
      VaoPpStats simd, scalar;
      run(f.g, s, Kernel::Simd, 0, &simd);
      run(f.g, s, Kernel::Scalar, 0, &scalar);
      EXPECT_EQ(simd.pixels, scalar.pixels) << scene;
      EXPECT_EQ(simd.prepass_pixels, scalar.prepass_pixels) << scene;
      EXPECT_EQ(simd.culled, scalar.culled) << scene;
      EXPECT_NEAR(double(simd.samples), double(scalar.samples), 1e-4 * double(scalar.samples))
          << scene;
    }
  }
}

TEST(VaoSimd, SameBitsForAnyThreadCount) {
  const Striped st("blocks", 203, 117);
  for (const auto& [name, s] : vao_variants(0.25f)) {
    expect_same_bits_for_thread_counts(
        [&](int threads) { return run(st.g, s, Kernel::Simd, threads); }, name);
  }
  auto pp = vao_pp_variants(0.25f);
  VaoPpSettings bleeding;
  bleeding.radius = 0.25f;
  bleeding.color_bleeding = true;
  pp.push_back({"vao_pp colour bleeding", bleeding});
  for (const auto& [name, s] : pp) {
    expect_same_bits_for_thread_counts(
        [&](int threads) { return run(st.g, s, Kernel::Simd, threads); }, name);
  }
}

TEST(VaoSimd, TinyImagesAndHardInputs) {
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{{1, 1}, {7, 3}, {13, 5}, {17, 2}}) {
    SceneFixture f("blocks", w, h);
    const std::string what = std::to_string(w) + "x" + std::to_string(h);
    VaoSettings s;
    s.radius = 0.5f;
    const Image simd = run(f.g, s, Kernel::Simd);
    expect_kernels_agree(simd, run(f.g, s, Kernel::Scalar),
                         KernelTolerance::worst_only(worst_tolerance(s.samples)), what);
    expect_in_unit_interval(simd, what);
    VaoPpSettings p;
    p.radius = 0.5f;
    const Image simd_pp = run(f.g, p, Kernel::Simd);
    expect_kernels_agree(simd_pp, run(f.g, p, Kernel::Scalar),
                         KernelTolerance::worst_only(worst_tolerance(p.samples)), what);
    expect_in_unit_interval(simd_pp, what);
  }
  // NaN, infinite, zero and negative depths are background: AO 1, and they occlude nothing.
  const SceneFixture f("blocks", 41, 23);
  HostileDepths hostile(f.g);
  hostile.every_third_pixel_of_rows();
  const GBuffer& g = hostile.g;
  VaoSettings s;
  s.radius = 0.5f;
  const Image simd = run(g, s, Kernel::Simd);
  expect_kernels_agree(simd, run(g, s, Kernel::Scalar),
                       KernelTolerance::worst_only(worst_tolerance(s.samples)),
                       "hostile depths, vao");
  VaoPpSettings p;
  p.radius = 0.5f;
  p.filter = false;  // the filter keeps a background pixel's value: 1
  const Image simd_pp = run(g, p, Kernel::Simd);
  expect_kernels_agree(simd_pp, run(g, p, Kernel::Scalar),
                       KernelTolerance::worst_only(worst_tolerance(p.samples)),
                       "hostile depths, vao_pp");
  hostile.expect_ao_one(simd, "vao");
  hostile.expect_ao_one(simd_pp, "vao_pp");
}

// The filter's SIMD kernel takes the same taps in the same order: on a constant image it
// returns it bit for bit (every weight times the constant, summed and divided by the summed
// weights), and elsewhere it differs from the scalar filter by the fused multiply-adds'
// rounding only.
TEST(VaoSimd, BilateralFilterMatchesScalar) {
  const SceneFixture f("blocks", 203, 117);
  Image image(203, 117, 4);
  for (int y = 0; y < 117; ++y)
    for (int x = 0; x < 203; ++x)
      for (int c = 0; c < 4; ++c) image(x, y, c) = float((x * 13 + y * 7 + c * 3) % 17) / 16.0f;
  for (int taps : {1, 3, 7, 63}) {
    const Image simd = cross_bilateral_filter_simd(image.view(), f.g, taps, 2.0f, 0.25f, 2);
    const Image scalar = cross_bilateral_filter(image.view(), f.g, taps, 2.0f, 0.25f, 2);
    const auto k = kernel_difference(simd, scalar);
    EXPECT_LE(k.worst, 1e-6) << taps;  // a few ulps of values in [0, 1]
  }
  const Image ones(203, 117, 1, 1.0f);
  EXPECT_EQ(cross_bilateral_filter_simd(ones.view(), f.g, 5, 2.0f, 0.25f).pixels(), ones.pixels());
  EXPECT_THROW(cross_bilateral_filter_simd(ones.view(), f.g, 4, 2.0f, 0.25f),
               std::invalid_argument);
}

}  // namespace
}  // namespace aolab
