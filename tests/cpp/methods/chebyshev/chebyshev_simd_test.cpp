// Chebyshev AO's SIMD kernel (chebyshev_simd.cpp) against its scalar code, the oracle: every
// setting, on analytic scenes and on committed reference scenes, the visibility and the
// moments; the same bits for any thread count; hard sizes and inputs. The known-answer tests
// of chebyshev_test.cpp, test_chebyshev.py and the conformance suites run the SIMD kernel too
// (it is the default).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/methods/chebyshev/chebyshev.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::expect_in_unit_interval;
using testing::expect_kernels_agree;
using testing::expect_same_bits_for_thread_counts;
using testing::HostileDepths;
using testing::kernel_difference;
using testing::ReferenceScene;
using testing::run_kernel;
using testing::SceneFixture;

// The tolerance is zero: every lane performs the scalar pixel's float and double operations in
// the same order (taps −r … r, rows −ry … ry, the same shifts and divisions), with no fused
// multiply-add on either side (the kernel's file turns GCC's contraction off; the scalar code
// is built without -march), and IEEE +, −, ×, ÷ and √ round the same in a lane as in a scalar
// register. So the kernels must agree bit for bit, not merely within rounding.
constexpr double kWorstTolerance = 0.0;

Image run_moments(const GBuffer& g, const ChebyshevSettings& s, Kernel kernel) {
  RunOptions options;
  options.kernel = kernel;
  return chebyshev_moments(g, s, options);
}

void expect_kernels_agree(const GBuffer& g, const ChebyshevSettings& s, const std::string& what) {
  const Image simd = run_kernel(chebyshev, g, s, Kernel::Simd),
              scalar = run_kernel(chebyshev, g, s, Kernel::Scalar);
  const auto k = kernel_difference(simd, scalar);
  EXPECT_LE(k.worst, kWorstTolerance) << what << ": mean " << k.mean << ", p99.9 " << k.p999;
  EXPECT_EQ(simd.pixels(), scalar.pixels()) << what;  // also ±0 and NaN bits
  const auto m =
      kernel_difference(run_moments(g, s, Kernel::Simd), run_moments(g, s, Kernel::Scalar));
  EXPECT_LE(m.worst, kWorstTolerance) << what << " (moments)";
}

// Every setting away from its default at least once.
std::vector<std::pair<std::string, ChebyshevSettings>> variants(float radius) {
  std::vector<std::pair<std::string, ChebyshevSettings>> out;
  ChebyshevSettings base;
  base.radius = radius;
  out.push_back({"defaults", base});
  auto add = [&](const std::string& name, auto change) {
    ChebyshevSettings s = base;
    change(s);
    out.push_back({name, s});
  };
  add("medium preset", [](ChebyshevSettings& s) { s.max_kernel_radius = 32; });
  add("max_kernel_radius 128", [](ChebyshevSettings& s) { s.max_kernel_radius = 128; });
  add("fixed 8", [](ChebyshevSettings& s) { s.kernel_mode = int(ChebyshevKernel::Fixed); });
  add("fixed 1", [](ChebyshevSettings& s) {
    s.kernel_mode = int(ChebyshevKernel::Fixed), s.kernel_radius = 1;
  });
  add("fixed 37", [](ChebyshevSettings& s) {
    s.kernel_mode = int(ChebyshevKernel::Fixed), s.kernel_radius = 37;
  });
  add("fixed 0", [](ChebyshevSettings& s) {
    s.kernel_mode = int(ChebyshevKernel::Fixed), s.kernel_radius = 0;
  });
  add("variance_bias 0", [](ChebyshevSettings& s) { s.variance_bias = 0.0f; });
  add("variance_bias 0.01", [](ChebyshevSettings& s) { s.variance_bias = 0.01f; });
  add("eq. 2", [](ChebyshevSettings& s) { s.ignore_unoccluded = false; });
  add("no range check", [](ChebyshevSettings& s) { s.range_check = false; });
  add("eq. 2, no range check, no bias", [](ChebyshevSettings& s) {
    s.ignore_unoccluded = s.range_check = false, s.variance_bias = 0.0f;
  });
  add("no shrinking", [](ChebyshevSettings& s) { s.shrink_at_background = false; });
  add("radius x8", [radius](ChebyshevSettings& s) { s.radius = 8.0f * radius; });
  add("radius /8", [radius](ChebyshevSettings& s) { s.radius = radius / 8.0f; });
  return out;
}

TEST(ChebyshevSimd, MatchesScalarOnAnalyticScenes) {
  for (const char* scene : {"blocks", "wall", "crease", "ceiling", "plane", "step"}) {
    const SceneFixture f(scene, 203, 117);  // widths that are no multiple of any vector length
    for (const auto& [name, s] : variants(scene == std::string("blocks") ? 0.25f : 1.0f))
      expect_kernels_agree(f.g, s, std::string(scene) + ", " + name);
  }
}

TEST(ChebyshevSimd, MatchesScalarOnReferenceScenes) {
  // street and engine hold background (8 % and 64 % of the pixels): shrunk windows, rows whose
  // references are the nearest valid pixel.
  for (const char* scene : {"room", "street", "grille", "engine"}) {
    const ReferenceScene reference(scene);
    const GBuffer& g = reference.g;
    const float radius = reference.radius;  // the scene's own R (its manifest.json)
    for (const auto& [name, s] : variants(radius)) {
      if (name != "defaults" && name != "medium preset" && name != "no shrinking") continue;
      expect_kernels_agree(g, s, std::string(scene) + ", " + name);
    }
  }
}

TEST(ChebyshevSimd, SameBitsForAnyThreadCount) {
  const SceneFixture f("blocks", 203, 117);
  for (const auto& [name, s] : variants(0.25f)) {
    expect_same_bits_for_thread_counts(
        [&](int threads) { return run_kernel(chebyshev, f.g, s, Kernel::Simd, threads); }, name);
  }
}

TEST(ChebyshevSimd, TinyImagesAndHardInputs) {
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{
           {1, 1}, {2, 1}, {1, 9}, {7, 3}, {13, 5}, {17, 2}, {33, 4}}) {
    SceneFixture f("blocks", w, h);
    for (const auto& [name, s] : variants(0.5f)) {
      const Image simd = run_kernel(chebyshev, f.g, s, Kernel::Simd);
      EXPECT_EQ(simd.pixels(), run_kernel(chebyshev, f.g, s, Kernel::Scalar).pixels())
          << w << "x" << h << name;
      expect_in_unit_interval(simd, std::to_string(w) + "x" + std::to_string(h));
    }
  }
  // NaN, infinite, zero and negative depths are background: AO 1, and they enter no window
  // (shrunk around them, or skipped and counted); rows and columns of them, and a row that is
  // background but for one pixel (its reference is that pixel's depth).
  const SceneFixture f("blocks", 83, 47);
  HostileDepths hostile(f.g);
  hostile.every_third_pixel_of_rows();
  const std::vector<float> bad = testing::hostile_depth_values();
  for (int y = 0; y < 47; ++y) hostile.set(70, y, bad[y % 4]);
  for (int x = 0; x < 83; ++x)
    if (x != 41) hostile.set(x, 30, bad[x % 4]);
  for (int y = 35; y < 47; ++y)
    for (int x = 0; x < 20; ++x) hostile.set(x, y, bad[(x + y) % 4]);
  for (const auto& [name, s] : variants(0.5f)) {
    expect_kernels_agree(hostile.g, s, "hostile depth, " + name);
    hostile.expect_ao_one(run_kernel(chebyshev, hostile.g, s, Kernel::Simd), name);
  }
}

}  // namespace
}  // namespace aolab
