// Helpers shared by the C++ tests: analytic scenes as G-buffers, a temporary folder per
// test, and the message of an expected std::invalid_argument.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/base/gbuffer.h"
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
