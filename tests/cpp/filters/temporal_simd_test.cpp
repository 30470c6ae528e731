// The accumulation step's SIMD kernel against its scalar code: the same bits on every pixel,
// for every instruction set compiled in, on frames that take every path (background, steps in
// depth that reject taps, turned normals, motion that is fractional, whole, off-screen or
// NaN, widths that leave a tail), with each clamp.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "core/filters/temporal.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::random_image;

/// Frame k of a small scene: a plane at depth 2 with boxes whose depth and normals change
/// from frame to frame, a background hole, and motion of every kind.
struct Frame {
  Image depth, normal, ao, motion;
  GBuffer g;
  Frame(int w, int h, int k)
      : depth(w, h, 1), normal(w, h, 3), ao(random_image(w, h, 100 + k)), motion(w, h, 2) {
    const Image jitter = random_image(w, h, 200 + k);
    const Image offsets = random_image(w, 2 * h, 300 + k, -3.0f, 3.0f);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const bool box = ((x + k) / 5 + y / 4) % 3 == 0;
        depth(x, y) = box ? 1.5f + 0.1f * float(k % 2) : 2.0f + 0.01f * jitter(x, y);
        normal(x, y, 0) = box ? 0.6f * float(k % 2) : 0.0f;
        normal(x, y, 1) = 0.1f * jitter(x, y);
        normal(x, y, 2) = 1.0f;
        const float dx = offsets.data()[2 * (y * w + x)], dy = offsets.data()[2 * (y * w + x) + 1];
        const int kind = (x * 7 + y * 3 + k) % 5;  // fractional, whole, far off-screen, NaN
        motion(x, y, 0) = kind == 1 ? std::round(dx) : kind == 2 ? dx * 40.0f : dx;
        motion(x, y, 1) = kind == 1 ? std::round(dy) : dy;
        if (kind == 3) motion(x, y, 0) = std::numeric_limits<float>::quiet_NaN();
      }
    for (int y = h / 3; y < h / 2; ++y)
      for (int x = w / 4; x < w / 3; ++x) depth(x, y) = std::numeric_limits<float>::infinity();
    g.depth = depth.view();
    g.normal = normal.view();
    g.camera = {20, 20, 0.5f * float(w), 0.5f * float(h)};
  }
};

void expect_kernels_agree(int w, int h, const TemporalSettings& s, const std::string& what) {
  TemporalHistory scalar, simd;
  for (int k = 0; k < 5; ++k) {
    const Frame f(w, h, k);
    const TemporalResult a =
        accumulate(f.ao.view(), f.g, f.motion.view(), scalar, s, 2, TemporalKernel::Scalar);
    const TemporalResult b =
        accumulate(f.ao.view(), f.g, f.motion.view(), simd, s, 2, TemporalKernel::Simd);
    int differ = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (std::bit_cast<std::uint32_t>(a.accumulated(x, y)) !=
                std::bit_cast<std::uint32_t>(b.accumulated(x, y)) &&
            differ++ == 0)
          ADD_FAILURE() << what << ", frame " << k << ": pixel (" << x << ", " << y << ") scalar "
                        << a.accumulated(x, y) << ", SIMD " << b.accumulated(x, y);
    EXPECT_EQ(differ, 0) << what << ", frame " << k;
    EXPECT_EQ(a.disoccluded.pixels(), b.disoccluded.pixels()) << what << ", frame " << k;
    EXPECT_EQ(scalar.length.pixels(), simd.length.pixels()) << what << ", frame " << k;
  }
}

std::vector<std::pair<std::string, TemporalSettings>> variants() {
  std::vector<std::pair<std::string, TemporalSettings>> out;
  for (const auto& [name, clamp] :
       {std::pair{"off", TemporalClamp::Off}, std::pair{"minmax", TemporalClamp::MinMax},
        std::pair{"variance", TemporalClamp::Variance}}) {
    TemporalSettings s;
    s.clamp = int(clamp);
    out.emplace_back(name, s);
  }
  TemporalSettings every_normal;
  every_normal.normal_tolerance = -1.0f;
  every_normal.alpha = 0.0f;
  every_normal.max_history = 3;
  out.emplace_back("normals kept, alpha 0, max_history 3", every_normal);
  return out;
}

TEST(TemporalSimd, SameBitsAsTheScalarCode) {
  for (const auto& [w, h] : {std::pair{64, 24}, std::pair{37, 19}, std::pair{3, 5}})
    for (const auto& [name, s] : variants())
      expect_kernels_agree(w, h, s, name + " at " + std::to_string(w) + "x" + std::to_string(h));
}

// Every instruction set compiled in that this machine runs, down to Highway's 1-lane target.
TEST(TemporalSimd, EveryCompiledTargetMatchesScalar) {
  const std::vector<std::int64_t> targets = hwy::SupportedAndGeneratedTargets();
  EXPECT_GE(targets.size(), 2u);
  for (const std::int64_t target : targets) {
    hwy::SetSupportedTargetsForTest(target);
    for (const auto& [name, s] : variants())
      expect_kernels_agree(41, 17, s, std::string(hwy::TargetName(target)) + ", " + name);
  }
  hwy::SetSupportedTargetsForTest(0);  // back to every target the machine has
}

}  // namespace
}  // namespace aolab
