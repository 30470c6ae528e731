// Helpers shared by the C++ tests: analytic scenes as G-buffers, a temporary folder per
// test, and the message of an expected std::invalid_argument.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/base/gbuffer.h"
#include "core/io/image_io.h"
#include "core/methods/registry.h"
#include "core/scenes/analytic_scenes.h"

namespace aolab::testing {

/// Owns an analytic scene and exposes it as a G-buffer view.
struct SceneFixture {
  AnalyticGBuffer scene;
  GBuffer g;
  explicit SceneFixture(const std::string& name, int w = 160, int h = 90,
                        const SettingValues& params = {})
      : scene(analytic_scene(name, w, h, params)) {
    g.depth = scene.depth.view();
    g.normal = scene.normal.view();
    g.camera = scene.camera;
  }
};

/// A committed reference scene (reference_scenes/NAME/reference.exr) as a G-buffer view, with
/// the AO radius R its manifest.json gives it (the radius the scene was rendered for). Neither
/// copied nor moved: `g` views `data`.
struct ReferenceScene {
  std::string name;
  GBufferData data;
  GBuffer g;
  float radius;
  explicit ReferenceScene(const std::string& scene)
      : name(scene),
        data(load_gbuffer(directory(scene) + "/reference.exr")),
        g(data.view()),
        radius(manifest_radius(scene)) {}
  ReferenceScene(const ReferenceScene&) = delete;
  ReferenceScene& operator=(const ReferenceScene&) = delete;

 private:
  static std::string directory(const std::string& scene) {
    return std::string(AOLAB_SOURCE_DIR) + "/reference_scenes/" + scene;
  }
  // The number after the manifest's "radius" key (the file's only one).
  static float manifest_radius(const std::string& scene) {
    std::ifstream in(directory(scene) + "/manifest.json");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t key = text.find("\"radius\"");
    if (key == std::string::npos) throw std::runtime_error("no radius in " + scene + "'s manifest");
    return std::stof(text.substr(text.find(':', key) + 1));
  }
};

/// Errors against the closed-form Cycles AO of an analytic scene: the mean and worst |error|
/// over the pixels at least `margin` px from the image border (nearer, samples leave the
/// screen) whose reference is finite.
struct ClosedFormErrors {
  double mean = 0, worst = 0;
  int pixels = 0;
};
inline ClosedFormErrors closed_form_errors(const SceneFixture& f, const Image& ao, int margin) {
  ClosedFormErrors e;
  for (int y = margin; y < ao.height() - margin; ++y)
    for (int x = margin; x < ao.width() - margin; ++x) {
      const float ref = f.scene.reference(x, y);
      if (!f.g.valid(x, y) || !std::isfinite(ref)) continue;
      const double err = std::abs(double(ao(x, y)) - ref);
      e.mean += err, e.worst = std::max(e.worst, err), ++e.pixels;
    }
  e.mean /= std::max(1, e.pixels);
  return e;
}

/// A 1-channel image of deterministic values in [lo, hi) from a 64-bit LCG, so tests need
/// no seeding policy.
inline Image random_image(int width, int height, std::uint64_t seed, float lo = 0.0f,
                          float hi = 1.0f) {
  Image image(width, height, 1);
  std::uint64_t state = seed * 6364136223846793005ull + 1442695040888963407ull;
  for (float& v : image.pixels()) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    const double u = double(state >> 11) / double(1ull << 53);
    v = lo + float(u) * (hi - lo);
  }
  return image;
}

/// The smallest AO over the G-buffer's valid pixels (1 if none).
inline float min_valid(const Image& ao, const GBuffer& g) {
  float m = 1.0f;
  for (int y = 0; y < ao.height(); ++y)
    for (int x = 0; x < ao.width(); ++x)
      if (g.valid(x, y)) m = std::min(m, ao(x, y));
  return m;
}

/// Mean |AO − closed-form reference| over the scene's geometry pixels with a finite reference
/// (for the scenes whose Cycles AO has a closed form: ceiling, wall, crease).
inline double mae_against_reference(const Image& ao, const SceneFixture& f) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < ao.height(); ++y)
    for (int x = 0; x < ao.width(); ++x) {
      const float ref = f.scene.reference(x, y);
      if (!f.g.valid(x, y) || !std::isfinite(ref)) continue;
      sum += std::abs(double(ao(x, y)) - ref), ++n;
    }
  return sum / n;
}

/// The mean of every pixel of a 1-channel image.
inline double mean_value(const Image& image) {
  double sum = 0;
  for (float v : image.pixels()) sum += v;
  return sum / double(image.pixels().size());
}

/// A seed moves a stochastic method's noise, not its expected value: the two runs differ and
/// their means agree within `tolerance`.
inline void expect_other_noise_same_mean(const Image& a, const Image& b, double tolerance) {
  EXPECT_NE(a.pixels(), b.pixels());
  EXPECT_NEAR(mean_value(a), mean_value(b), tolerance);
}

/// How far a method's SIMD kernel is from its scalar code (the oracle) on one G-buffer: the
/// mean, the 99.9th percentile and the largest |difference| over every pixel and channel.
struct KernelDifference {
  double mean = 0, p999 = 0, worst = 0;
};

inline KernelDifference kernel_difference(const Image& simd, const Image& scalar) {
  EXPECT_EQ(simd.width(), scalar.width());
  EXPECT_EQ(simd.height(), scalar.height());
  EXPECT_EQ(simd.channels(), scalar.channels());
  std::vector<double> d;
  d.reserve(simd.pixels().size());
  for (std::size_t i = 0; i < simd.pixels().size(); ++i)
    d.push_back(std::abs(double(simd.pixels()[i]) - double(scalar.pixels()[i])));
  KernelDifference k;
  if (d.empty()) return k;
  for (double v : d) k.mean += v;
  k.mean /= double(d.size());
  std::sort(d.begin(), d.end());
  k.p999 = d[std::min(d.size() - 1, std::size_t(0.999 * double(d.size())))];
  k.worst = d.back();
  return k;
}

/// The bounds a SIMD kernel's difference from its scalar code must keep (each test states the
/// reason for its values). An unchecked statistic is +infinity.
struct KernelTolerance {
  double mean, p999, worst;
  /// Only the largest difference bounded (tiny images, where a mean or a percentile over a
  /// handful of pixels says nothing).
  static KernelTolerance worst_only(double worst) {
    constexpr double kUnbounded = std::numeric_limits<double>::infinity();
    return {kUnbounded, kUnbounded, worst};
  }
};

/// Runs a method (any `Image method(const GBuffer&, const S&, const RunOptions&)`, e.g.
/// `alchemy`) with the given kernel and thread count (0 = all cores).
template <class S, class Method>
Image run_kernel(Method method, const GBuffer& g, const S& s, Kernel kernel, int threads = 0) {
  RunOptions options;
  options.kernel = kernel;
  options.threads = threads;
  return method(g, s, options);
}

/// Expects a SIMD kernel's result within `t` of the scalar code's; `what` names the case in
/// the failure messages. With the environment variable AOLAB_PRINT_KERNEL_DIFFERENCE set it
/// prints the measured differences, the numbers the tests' tolerance comments quote.
inline void expect_kernels_agree(const Image& simd, const Image& scalar, const KernelTolerance& t,
                                 const std::string& what) {
  const KernelDifference k = kernel_difference(simd, scalar);
  EXPECT_LE(k.mean, t.mean) << what;
  EXPECT_LE(k.p999, t.p999) << what;
  EXPECT_LE(k.worst, t.worst) << what;
  if (std::getenv("AOLAB_PRINT_KERNEL_DIFFERENCE"))
    std::printf("%s: mean %.3g p999 %.3g worst %.3g\n", what.c_str(), k.mean, k.p999, k.worst);
}

/// The same for a method and its settings on one G-buffer: runs both kernels on all cores.
template <class S, class Method>
void expect_kernels_agree(Method method, const GBuffer& g, const S& s, const KernelTolerance& t,
                          const std::string& what) {
  expect_kernels_agree(run_kernel(method, g, s, Kernel::Simd),
                       run_kernel(method, g, s, Kernel::Scalar), t, what);
}

/// Expects the same bits from 1, 2 and 3 threads: `run_with_threads(n)` returns the image
/// computed on n threads. Three threads cut the rows or tiles unevenly, so a result that
/// depended on where the work is split would differ.
template <class Run>
void expect_same_bits_for_thread_counts(Run run_with_threads, const std::string& what) {
  const Image one = run_with_threads(1);
  EXPECT_EQ(one.pixels(), run_with_threads(2).pixels()) << what << ", 2 threads";
  EXPECT_EQ(one.pixels(), run_with_threads(3).pixels()) << what << ", 3 threads";
}

/// The depths every method must treat as background (AO 1, occluding nothing): NaN, +infinity,
/// zero and negative.
inline std::vector<float> hostile_depth_values() {
  return {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), 0.0f,
          -1.0f};
}

/// A copy of a G-buffer whose depth can be overwritten at chosen pixels with hostile values
/// (`g` views the copy; the other passes and the camera are the source's). The pixels set are
/// remembered, so that a test can check AO 1 on every one of them. Neither copied nor moved:
/// `g` points into `depth`.
struct HostileDepths {
  Image depth;
  GBuffer g;
  std::vector<std::pair<int, int>> pixels;  ///< (x, y) of every pixel set

  explicit HostileDepths(const GBuffer& source)
      : depth(source.depth.width, source.depth.height, 1), g(source) {
    for (int y = 0; y < depth.height(); ++y)
      for (int x = 0; x < depth.width(); ++x) depth(x, y) = source.depth(x, y);
    g.depth = std::as_const(depth).view();
  }
  HostileDepths(const HostileDepths&) = delete;
  HostileDepths& operator=(const HostileDepths&) = delete;

  void set(int x, int y, float value) {
    depth(x, y) = value;
    pixels.push_back({x, y});
  }

  /// The pattern most tests use: value i of hostile_depth_values() on every third pixel of row
  /// first_row + row_step·i.
  HostileDepths& every_third_pixel_of_rows(int first_row = 4, int row_step = 5) {
    const std::vector<float> bad = hostile_depth_values();
    for (int i = 0; i < int(bad.size()); ++i)
      for (int x = 0; x < depth.width(); x += 3) set(x, first_row + row_step * i, bad[i]);
    return *this;
  }

  /// Expects AO exactly 1 on every pixel set.
  void expect_ao_one(const Image& ao, const std::string& what = "") const {
    for (const auto& [x, y] : pixels) EXPECT_EQ(ao(x, y), 1.0f) << what << " at " << x << "," << y;
  }
};

/// Expects every value of an image in [0, 1] (false for NaN too).
inline void expect_in_unit_interval(const Image& image, const std::string& what) {
  for (float v : image.pixels()) EXPECT_TRUE(v >= 0.0f && v <= 1.0f) << what;
}

/// The sizes below one vector of any instruction set (and their row tails): 1×1, 7×3, 13×5,
/// 17×2.
inline std::vector<std::pair<int, int>> tiny_image_sizes() {
  return {{1, 1}, {7, 3}, {13, 5}, {17, 2}};
}

/// The hard inputs every SIMD kernel is tested on, with the settings `s`: the `blocks` scene at
/// each of `sizes` (the SIMD result within `worst` of the scalar one, and in [0, 1]); then on
/// 41×23 with hostile depths (HostileDepths::every_third_pixel_of_rows: background, so AO 1
/// there), again within `worst` of the scalar result.
template <class S, class Method>
void expect_tiny_images_and_hostile_depths_handled(
    Method method, const S& s, double worst,
    const std::vector<std::pair<int, int>>& sizes = tiny_image_sizes()) {
  for (const auto& [w, h] : sizes) {
    const SceneFixture f("blocks", w, h);
    const Image simd = run_kernel(method, f.g, s, Kernel::Simd);
    const std::string what = std::to_string(w) + "x" + std::to_string(h);
    expect_kernels_agree(simd, run_kernel(method, f.g, s, Kernel::Scalar),
                         KernelTolerance::worst_only(worst), what);
    expect_in_unit_interval(simd, what);
  }
  const SceneFixture f("blocks", 41, 23);
  HostileDepths hostile(f.g);
  hostile.every_third_pixel_of_rows();
  const Image simd = run_kernel(method, hostile.g, s, Kernel::Simd);
  expect_kernels_agree(simd, run_kernel(method, hostile.g, s, Kernel::Scalar),
                       KernelTolerance::worst_only(worst), "hostile depths");
  hostile.expect_ao_one(simd, "hostile depths");
}

/// A fixture owning a fresh temporary folder, removed after the test.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device rd;
    dir_ = std::filesystem::temp_directory_path() / ("aolab_test_" + std::to_string(rd()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::filesystem::path dir_;
};

/// The message of the std::invalid_argument thrown by f, or "" if none is thrown.
template <class F>
std::string invalid_argument_message(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace aolab::testing
