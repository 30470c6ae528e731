// Pyramid HBAO's SIMD kernel (pyramid_hbao_simd.cpp) against its scalar code, the oracle:
// every setting, on analytic scenes and on committed reference scenes; the same bits for any
// thread count; hard sizes and inputs; and its pyramid (gather_pyramid.h), texel for texel
// DepthPyramid's. The known-answer tests of pyramid_hbao_test.cpp and the conformance suites
// run the SIMD kernel too (it is the default).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "core/io/image_io.h"
#include "core/methods/pyramid_hbao/depth_pyramid.h"
#include "core/methods/pyramid_hbao/gather_pyramid.h"
#include "core/methods/pyramid_hbao/pyramid_hbao.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::kernel_difference;
using testing::SceneFixture;

// The two kernels read the same texels and evaluate the same expressions; they differ where
// the SIMD kernel fuses a multiply and an add, and takes the directions' sin and cos from
// Highway (a few ulps from the C library's). So a sample's term differs by an ulp or two,
// and a sample whose height above P's tangent plane lies within an ulp of the rounding
// tolerance (docs/methods/pyramid_hbao.md, "Rounding") counts in one kernel and not the
// other; its term is then about that tolerance times depth over distance, 1e-6 to 1e-4
// (measured: mean ≤ 2.1e-7 and 99.9th percentile ≤ 1.9e-5 on `room`, below 1e-7 on the
// analytic scenes). Rarely, an ulp moves a read across a texel edge, where it snaps (the
// SIMD kernel computes ⌊x / K^l⌋ where the scalar code computes ⌊⌊x⌋ / K^l⌋), or
// across the image's edge, where the SIMD march ends at a precomputed t instead of testing
// the read's position: that changes one direction's term, by at most its whole share of A,
// 1/D (each term lies in [0, 1]; the Gaussian, a weighted mean, cannot make it larger;
// measured worst 0.019 on `blocks` at 1280×720, 0.017 on `room`).
constexpr double kMeanTolerance = 1e-5;
constexpr double kP999Tolerance = 1e-4;

double worst_tolerance(const PyramidHbaoSettings& s) { return 1.0 / s.directions; }

Image run(const GBuffer& g, const PyramidHbaoSettings& s, Kernel kernel, int threads = 0) {
  RunOptions options;
  options.kernel = kernel;
  options.threads = threads;
  return pyramid_hbao(g, s, options);
}

void expect_kernels_agree(const GBuffer& g, const PyramidHbaoSettings& s, const std::string& what) {
  const auto k = kernel_difference(run(g, s, Kernel::Simd), run(g, s, Kernel::Scalar));
  EXPECT_LE(k.mean, kMeanTolerance) << what;
  EXPECT_LE(k.p999, kP999Tolerance) << what;
  EXPECT_LE(k.worst, worst_tolerance(s)) << what;
}

// Every setting away from its default at least once. The base leaves the Gaussian out, as
// the presets do, so that a difference is not smoothed away; "gaussian" puts it back.
std::vector<std::pair<std::string, PyramidHbaoSettings>> variants(float radius) {
  std::vector<std::pair<std::string, PyramidHbaoSettings>> out;
  PyramidHbaoSettings base;
  base.radius = radius;
  base.gaussian_filter = false;
  out.push_back({"defaults", base});
  auto add = [&](const std::string& name, auto change) {
    PyramidHbaoSettings s = base;
    change(s);
    out.push_back({name, s});
  };
  add("gaussian", [](PyramidHbaoSettings& s) { s.gaussian_filter = true; });
  add("directions 5, samples 3", [](PyramidHbaoSettings& s) { s.directions = 5, s.samples = 3; });
  add("levels 2", [](PyramidHbaoSettings& s) { s.levels = 2; });
  add("levels 1, samples 9", [](PyramidHbaoSettings& s) { s.levels = 1, s.samples = 9; });
  add("reduction 2", [](PyramidHbaoSettings& s) { s.reduction = 2; });
  add("reduction 5, samples 2", [](PyramidHbaoSettings& s) { s.reduction = 5, s.samples = 2; });
  add("attenuation none",
      [](PyramidHbaoSettings& s) { s.attenuation = int(PyramidHbaoAttenuation::None); });
  add("no rotation", [](PyramidHbaoSettings& s) { s.rotation = false; });
  add("no random directions", [](PyramidHbaoSettings& s) { s.random_directions = false; });
  add("no random start", [](PyramidHbaoSettings& s) { s.random_start = false; });
  add("no randomness",
      [](PyramidHbaoSettings& s) { s.rotation = s.random_directions = s.random_start = false; });
  add("directions 1", [](PyramidHbaoSettings& s) { s.directions = 1; });
  add("seed 7", [](PyramidHbaoSettings& s) { s.seed = 7; });
  return out;
}

TEST(PyramidHbaoSimd, MatchesScalarOnAnalyticScenes) {
  for (const char* scene : {"blocks", "wall", "crease", "ceiling", "plane", "step"}) {
    const SceneFixture f(scene, 203, 117);  // widths that are no multiple of any vector length
    for (const auto& [name, s] : variants(scene == std::string("blocks") ? 0.25f : 1.0f))
      expect_kernels_agree(f.g, s, std::string(scene) + ", " + name);
  }
}

TEST(PyramidHbaoSimd, MatchesScalarAtLargeAndTinyRadii) {
  const SceneFixture f("blocks", 203, 117);
  for (float radius : {1e-4f, 0.05f, 3.0f, 1e3f, 1e30f}) {
    PyramidHbaoSettings s;
    s.radius = radius;
    s.gaussian_filter = false;
    expect_kernels_agree(f.g, s, "R = " + std::to_string(radius));
  }
}

TEST(PyramidHbaoSimd, MatchesScalarOnReferenceScenes) {
  for (const char* scene : {"room", "street", "grille"}) {
    const GBufferData data = load_gbuffer(std::string(AOLAB_SOURCE_DIR) + "/reference_scenes/" +
                                          scene + "/reference.exr");
    const GBuffer g = data.view();
    // The scenes' own R (manifest.json): room and grille 0.5, street 0.3.
    const float radius = scene == std::string("street") ? 0.3f : 0.5f;
    for (const auto& [name, s] : variants(radius)) {
      if (name != "defaults" && name != "gaussian" && name != "attenuation none" &&
          name != "reduction 2")
        continue;
      expect_kernels_agree(g, s, std::string(scene) + ", " + name);
    }
  }
}

TEST(PyramidHbaoSimd, SameBitsForAnyThreadCount) {
  const SceneFixture f("blocks", 203, 117);
  for (const auto& [name, s] : variants(0.25f)) {
    const Image one = run(f.g, s, Kernel::Simd, 1);
    EXPECT_EQ(one.pixels(), run(f.g, s, Kernel::Simd, 2).pixels()) << name;
    EXPECT_EQ(one.pixels(), run(f.g, s, Kernel::Simd, 3).pixels()) << name;
  }
}

TEST(PyramidHbaoSimd, TinyImagesAndHardInputs) {
  for (const auto& [w, h] :
       std::vector<std::pair<int, int>>{{1, 1}, {7, 3}, {13, 5}, {17, 2}, {1, 40}, {300, 1}}) {
    SceneFixture f("blocks", w, h);
    PyramidHbaoSettings s;
    s.radius = 0.5f;
    const Image simd = run(f.g, s, Kernel::Simd);
    const auto k = kernel_difference(simd, run(f.g, s, Kernel::Scalar));
    EXPECT_LE(k.worst, worst_tolerance(s)) << w << "x" << h;
    for (float v : simd.pixels()) EXPECT_TRUE(v >= 0.0f && v <= 1.0f) << w << "x" << h;
  }
  // NaN, infinite, zero and negative depths are background: AO 1, and they occlude nothing.
  SceneFixture f("blocks", 41, 23);
  Image depth(41, 23, 1);
  for (int y = 0; y < 23; ++y)
    for (int x = 0; x < 41; ++x) depth(x, y) = f.g.depth(x, y);
  const float bad[] = {std::numeric_limits<float>::quiet_NaN(),
                       std::numeric_limits<float>::infinity(), 0.0f, -1.0f};
  for (int i = 0; i < 4; ++i)
    for (int x = 0; x < 41; x += 3) depth(x, 4 + 5 * i) = bad[i];
  GBuffer g = f.g;
  g.depth = std::as_const(depth).view();
  PyramidHbaoSettings s;
  s.radius = 0.5f;
  s.gaussian_filter = false;
  const Image simd = run(g, s, Kernel::Simd);
  const auto k = kernel_difference(simd, run(g, s, Kernel::Scalar));
  EXPECT_LE(k.mean, kMeanTolerance);
  EXPECT_LE(k.worst, worst_tolerance(s));
  for (int i = 0; i < 4; ++i)
    for (int x = 0; x < 41; x += 3) EXPECT_EQ(simd(x, 4 + 5 * i), 1.0f);
}

// The SIMD kernel's pyramid holds DepthPyramid's texels bit for bit: the same depths (the sign
// bit marks a centroid that is not the footprint's centre, and only those), the same
// centroids, background where DepthPyramid has it, and a border of background.
TEST(GatherPyramid, EqualsDepthPyramidTexelForTexel) {
  struct Case {
    const char* scene;
    int w, h, k, levels;
  };
  for (const Case& c :
       {Case{"blocks", 203, 117, 3, 0}, Case{"blocks", 97, 61, 2, 0}, Case{"step", 160, 90, 4, 3},
        Case{"wall", 81, 27, 3, 0}, Case{"blocks", 1, 1, 3, 0}, Case{"ceiling", 300, 1, 5, 0}}) {
    SceneFixture f(c.scene, c.w, c.h);
    // Some background, including whole coarse texels, to exercise the marks.
    Image depth(c.w, c.h, 1);
    for (int y = 0; y < c.h; ++y)
      for (int x = 0; x < c.w; ++x)
        depth(x, y) = (x + 2 * y) % 11 == 0 || (x < 9 && y < 9) ? 1e10f : f.g.depth(x, y);
    GBuffer g = f.g;
    g.depth = std::as_const(depth).view();
    const DepthPyramid a(g, c.k, c.levels, 2);
    const GatherPyramid b(g, c.k, c.levels, 3);
    ASSERT_EQ(a.levels(), b.levels()) << c.scene;
    for (int l = 0; l < a.levels(); ++l) {
      const DepthPyramidLevel& la = a.level(l);
      const GatherPyramidLevel& lb = b.level(l);
      ASSERT_EQ(la.width, lb.width);
      ASSERT_EQ(la.height, lb.height);
      ASSERT_EQ(la.scale, lb.scale);
      ASSERT_EQ(lb.stride, lb.width + 2);
      for (int y = -1; y <= la.height; ++y)
        for (int x = -1; x <= la.width; ++x) {
          const float d = lb.depth[lb.at(x, y)];
          if (x < 0 || y < 0 || x == la.width || y == la.height) {
            EXPECT_TRUE(std::isnan(d)) << "border " << x << "," << y;
            continue;
          }
          const PyramidTexel& t = la(x, y);
          if (std::isnan(t.depth)) {
            EXPECT_TRUE(std::isnan(d)) << l << ": " << x << "," << y;
            continue;
          }
          ASSERT_EQ(std::abs(d), t.depth) << l << ": " << x << "," << y;
          const bool centred = t.x == float(double(la.scale) * (x + 0.5)) &&
                               t.y == float(double(la.scale) * (y + 0.5));
          EXPECT_EQ(d > 0.0f, centred) << l << ": " << x << "," << y;
          if (l > 0) {
            EXPECT_EQ(lb.cx[lb.at(x, y)], t.x) << l << ": " << x << "," << y;
            EXPECT_EQ(lb.cy[lb.at(x, y)], t.y) << l << ": " << x << "," << y;
          }
        }
    }
  }
}

TEST(GatherPyramid, RejectsWhatDepthPyramidRejects) {
  const SceneFixture f("blocks", 16, 9);
  EXPECT_THROW(GatherPyramid(f.g, 1), std::invalid_argument);
  EXPECT_THROW(GatherPyramid(f.g, 65), std::invalid_argument);
  EXPECT_THROW(GatherPyramid(f.g, 3, -1), std::invalid_argument);
}

}  // namespace
}  // namespace aolab
