// Known answers for GTAO (Jimenez et al. 2016): the inner integral, the closed forms of the
// analytic scenes where the occluder is in the depth buffer, the multi-bounce fit, the
// thickness heuristic, the normalisations, the seed. What every method promises (planes,
// background, threads, settings errors) is conformance_test's.
#include "core/methods/gtao/gtao.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::closed_form_errors;
using testing::ClosedFormErrors;
using testing::expect_other_noise_same_mean;
using testing::SceneFixture;

// Tolerances of the closed-form tests, about twice the measured errors (docs/methods/gtao.md).
constexpr double kClosedFormMean = 0.006, kClosedFormWorst = 0.04;

// Many slices and steps, no randomness: what is left is the method, not its noise.
GtaoSettings exact_settings(float radius) {
  GtaoSettings s;
  s.radius = radius;
  s.slices = 16;
  s.steps = 32;
  s.random_rotation = s.jitter = false;
  return s;
}

// Eq. 7 is ∫_0^h cos(θ − n)|sin θ| dθ (signed: negative h integrates towards side 1), and the
// two sides of an open slice sum to cos n + n sin n.
TEST(Gtao, ArcIsTheInnerIntegral) {
  const double pi = std::numbers::pi;
  for (double n : {-1.2, -0.4, 0.0, 0.3, 1.0, 1.5})
    for (double h : {-1.4, -0.7, -0.1, 0.2, 0.9, 1.6, 2.5}) {
      const int m = 20000;
      double sum = 0.0;
      for (int i = 0; i < m; ++i) {
        const double theta = h * (i + 0.5) / m;
        sum += std::cos(theta - n) * std::abs(std::sin(theta));
      }
      EXPECT_NEAR(gtao_arc(h, n), sum * std::abs(h) / m, 1e-7) << "h " << h << " n " << n;
    }
  for (double n : {-1.5, -0.5, 0.0, 0.7, 1.5})
    EXPECT_NEAR(gtao_arc(n - pi / 2, n) + gtao_arc(n + pi / 2, n), std::cos(n) + n * std::sin(n),
                1e-12);
}

// `wall` and `crease` hold their occluder in the depth buffer, like a height field: GTAO
// converges to Cycles' closed form there (measured at these settings: MAE wall 0.0032,
// crease 0.0024; worst 0.022, 0.015).
TEST(Gtao, WallAndCreaseMatchTheClosedForm) {
  for (const char* scene : {"wall", "crease"}) {
    SceneFixture f(scene, 320, 180, {{"radius", 1.0}});
    const ClosedFormErrors e = closed_form_errors(f, gtao(f.g, exact_settings(1.0f)), 40);
    ASSERT_GT(e.pixels, 10000);
    EXPECT_LT(e.mean, kClosedFormMean) << scene;
    EXPECT_LT(e.worst, kClosedFormWorst) << scene;
  }
}

// Under a ceiling farther than R nothing is within reach: exactly 1.
TEST(Gtao, CeilingBeyondTheRadiusIsOne) {
  SceneFixture f("ceiling", 256, 144);
  GtaoSettings s;
  s.radius = 0.9f;
  EXPECT_EQ(testing::min_valid(gtao(f.g, s), f.g), 1.0f);
}

TEST(Gtao, MultiBounceBrightensByTheFit) {
  SceneFixture f("blocks", 160, 90);
  GtaoSettings off;
  off.radius = 0.5f;
  GtaoSettings on = off;
  on.multi_bounce = true;
  on.albedo = 0.6f;
  const Image a = gtao(f.g, off), b = gtao(f.g, on);
  int brighter = 0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i) {
    const float ao = a.pixels()[i];
    ASSERT_EQ(b.pixels()[i], std::min(1.0f, gtao_multi_bounce(ao, 0.6f)));
    ASSERT_GE(b.pixels()[i], ao);
    // AO' = ((a·AO + b)·AO + c)·AO with the memo's coefficients, written out again.
    const double rho = 0.6, x = ao;
    const double fit =
        ((((2.0404 * rho - 0.3324) * x) + (-4.7951 * rho + 0.6417)) * x + (2.7552 * rho + 0.6903)) *
        x;
    EXPECT_NEAR(b.pixels()[i], std::min(1.0, std::max(x, fit)), 1e-5);
    brighter += b.pixels()[i] > ao;
  }
  EXPECT_GT(brighter, 1000);
}

// The thickness heuristic only ever lowers a horizon, so it only brightens; off, it is the
// plain max (the default result, bit for bit).
TEST(Gtao, ThicknessHeuristicOnlyBrightens) {
  SceneFixture f("blocks", 160, 90);
  GtaoSettings plain;
  plain.radius = 0.5f;
  plain.steps = 8;
  GtaoSettings thick = plain;
  thick.thickness = 0.5f;
  GtaoSettings zero = plain;
  zero.thickness = 0.0f;
  const Image a = gtao(f.g, plain), b = gtao(f.g, thick);
  EXPECT_EQ(a.pixels(), gtao(f.g, zero).pixels());
  int brighter = 0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i) {
    ASSERT_GE(b.pixels()[i], a.pixels()[i] - 1e-6f) << i;
    brighter += b.pixels()[i] > a.pixels()[i] + 1e-3f;
  }
  EXPECT_GT(brighter, 100);
}

// The memo's 1/N and the division by the unoccluded sum share their limit.
TEST(Gtao, NormalisationsAgreeWithManySlices) {
  SceneFixture f("blocks", 160, 90);
  GtaoSettings a = exact_settings(0.5f);
  a.slices = 64;
  a.steps = 16;
  GtaoSettings b = a;
  b.normalization = int(GtaoNormalization::Slices);
  const Image ua = gtao(f.g, a), ub = gtao(f.g, b);
  double diff = 0;
  for (std::size_t i = 0; i < ua.pixels().size(); ++i)
    diff += std::abs(ua.pixels()[i] - ub.pixels()[i]);
  EXPECT_LT(diff / double(ua.pixels().size()), 2e-3);
}

TEST(Gtao, SeedChangesNoiseButNotMean) {
  SceneFixture f("blocks", 200, 120);
  GtaoSettings s0, s1;
  s0.radius = s1.radius = 0.5f;
  s1.seed = 7;
  expect_other_noise_same_mean(gtao(f.g, s0), gtao(f.g, s1), 3e-3);
}

}  // namespace
}  // namespace aolab
