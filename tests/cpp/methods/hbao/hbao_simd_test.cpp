// HBAO's SIMD kernel (hbao_simd.cpp) against its scalar code, the oracle: every setting, on
// analytic scenes and on committed reference scenes; the same bits for any thread count; hard
// sizes and inputs. The known-answer tests of hbao_test.cpp and conformance_test.cpp run the
// SIMD kernel too (it is the default).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "core/io/image_io.h"
#include "core/methods/hbao/hbao.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::kernel_difference;
using testing::SceneFixture;

// The two kernels evaluate the same expressions; they differ where the SIMD kernel fuses a
// multiply and an add, takes 1/sqrt from the hardware estimate and a Newton step, and
// rotates the directions with Highway's sin/cos (a few ulps from the C library's). Almost
// every pixel then agrees to a few ulps (measured on every scene and setting below: mean
// ≤ 4e-6, 99.9th percentile ≤ 3e-5). On a few pixels in 10^5 such an ulp moves a sample
// across a texel edge where it snaps, or a horizon across the 1e-5 tie, which changes that
// direction's term: by at most its whole share of A, 2/N_d (sin h − sin t ≤ 2; measured
// worst 0.09 at N_d = 8, per-direction tangent on `ceiling`).
constexpr double kMeanTolerance = 1e-5;
constexpr double kP999Tolerance = 1e-4;

double worst_tolerance(const HbaoSettings& s) { return 2.0 / s.directions; }

Image run(const GBuffer& g, const HbaoSettings& s, Kernel kernel, int threads = 0) {
  RunOptions options;
  options.kernel = kernel;
  options.threads = threads;
  return hbao(g, s, options);
}

void expect_kernels_agree(const GBuffer& g, const HbaoSettings& s, const std::string& what) {
  const auto k = kernel_difference(run(g, s, Kernel::Simd), run(g, s, Kernel::Scalar));
  EXPECT_LE(k.mean, kMeanTolerance) << what;
  EXPECT_LE(k.p999, kP999Tolerance) << what;
  EXPECT_LE(k.worst, worst_tolerance(s)) << what;
}

// Every setting away from its default at least once (and the combinations the reference's
// definition uses).
std::vector<std::pair<std::string, HbaoSettings>> variants(float radius) {
  std::vector<std::pair<std::string, HbaoSettings>> out;
  HbaoSettings base;
  base.radius = radius;
  out.push_back({"defaults", base});
  auto add = [&](const std::string& name, auto change) {
    HbaoSettings s = base;
    change(s);
    out.push_back({name, s});
  };
  add("directions 5, steps 13", [](HbaoSettings& s) { s.directions = 5, s.steps = 13; });
  add("no rotation, no jitter", [](HbaoSettings& s) { s.random_rotation = s.jitter = false; });
  add("per-direction tangent", [](HbaoSettings& s) { s.per_sample_tangent = false; });
  add("cosine integral", [](HbaoSettings& s) { s.integral = int(HbaoIntegral::Cosine); });
  add("cosine, per-direction tangent", [](HbaoSettings& s) {
    s.integral = int(HbaoIntegral::Cosine), s.per_sample_tangent = false;
  });
  add("no attenuation", [](HbaoSettings& s) { s.attenuation = int(HbaoAttenuation::None); });
  add("incremental attenuation", [](HbaoSettings& s) { s.incremental_attenuation = true; });
  add("seed 7", [](HbaoSettings& s) { s.seed = 7; });
  // q = 2 px: on these small frames every level of the chain is read.
  add("far samples on the MIP chain", [](HbaoSettings& s) { s.mip_distance = 2.0f; });
  add("MIP chain, cosine, per-direction tangent", [](HbaoSettings& s) {
    s.mip_distance = 3.0f, s.integral = int(HbaoIntegral::Cosine), s.per_sample_tangent = false;
  });
  return out;
}

TEST(HbaoSimd, MatchesScalarOnAnalyticScenes) {
  for (const char* scene : {"blocks", "wall", "crease", "ceiling", "plane"}) {
    const SceneFixture f(scene, 203, 117);  // widths that are no multiple of any vector length
    for (const auto& [name, s] : variants(scene == std::string("blocks") ? 0.25f : 1.0f))
      expect_kernels_agree(f.g, s, std::string(scene) + ", " + name);
  }
}

TEST(HbaoSimd, MatchesScalarOnReferenceScenes) {
  for (const char* scene : {"room", "street", "grille"}) {
    const GBufferData data = load_gbuffer(std::string(AOLAB_SOURCE_DIR) + "/reference_scenes/" +
                                          scene + "/reference.exr");
    const GBuffer g = data.view();
    // The scenes' own R (manifest.json): room and grille 0.5, street 0.3.
    const float radius = scene == std::string("street") ? 0.3f : 0.5f;
    for (const auto& [name, s] : variants(radius)) {
      if (name != "defaults" && name != "cosine integral" && name != "no attenuation" &&
          name != "far samples on the MIP chain")
        continue;
      expect_kernels_agree(g, s, std::string(scene) + ", " + name);
    }
  }
}

TEST(HbaoSimd, SameBitsForAnyThreadCount) {
  const SceneFixture f("blocks", 203, 117);
  for (const auto& [name, s] : variants(0.25f)) {
    const Image one = run(f.g, s, Kernel::Simd, 1);
    EXPECT_EQ(one.pixels(), run(f.g, s, Kernel::Simd, 2).pixels()) << name;
    EXPECT_EQ(one.pixels(), run(f.g, s, Kernel::Simd, 3).pixels()) << name;
  }
}

TEST(HbaoSimd, TinyImagesAndHardInputs) {
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{{1, 1}, {7, 3}, {13, 5}, {17, 2}}) {
    SceneFixture f("blocks", w, h);
    for (float q : {0.0f, 1.0f}) {  // 1 px: the chain's levels down to a frame of one texel
      HbaoSettings s;
      s.radius = 0.5f, s.mip_distance = q;
      const Image simd = run(f.g, s, Kernel::Simd);
      const auto k = kernel_difference(simd, run(f.g, s, Kernel::Scalar));
      EXPECT_LE(k.worst, worst_tolerance(s)) << w << "x" << h << ", q " << q;
      for (float v : simd.pixels()) EXPECT_TRUE(v >= 0.0f && v <= 1.0f) << w << "x" << h;
    }
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
  HbaoSettings s;
  s.radius = 0.5f;
  const Image simd = run(g, s, Kernel::Simd);
  const auto k = kernel_difference(simd, run(g, s, Kernel::Scalar));
  EXPECT_LE(k.worst, worst_tolerance(s));
  for (int i = 0; i < 4; ++i)
    for (int x = 0; x < 41; x += 3) EXPECT_EQ(simd(x, 4 + 5 * i), 1.0f);
}

}  // namespace
}  // namespace aolab
