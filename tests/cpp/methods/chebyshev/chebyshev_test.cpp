// Chebyshev AO: the separable moments against a brute-force window in long double, the
// stability of σ² at large depths, the quantised window sizes, the visibility formulas. What
// every method promises (planes, background, threads, settings errors) is conformance_test's.
#include "core/methods/chebyshev/chebyshev.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::SceneFixture;

// The window of (x, y) as documented: half-widths min(r, x, w − 1 − x) and
// min(rv, y, h − 1 − y), background pixels left out.
struct BruteMoments {
  double n = 0, gap = 0, variance = 0;
};
BruteMoments brute(const GBuffer& g, int x, int y, int rh, int rv) {
  const int rx = std::min({rh, x, g.width() - 1 - x}), ry = std::min({rv, y, g.height() - 1 - y});
  long double n = 0, s1 = 0, s2 = 0;
  for (int j = -ry; j <= ry; ++j)
    for (int i = -rx; i <= rx; ++i) {
      if (!g.valid(x + i, y + j)) continue;
      const long double v = g.depth(x + i, y + j);
      n += 1, s1 += v, s2 += v * v;
    }
  const long double mean = s1 / n;
  long double var = 0;  // two-pass, exact enough
  for (int j = -ry; j <= ry; ++j)
    for (int i = -rx; i <= rx; ++i)
      if (g.valid(x + i, y + j))
        var += (g.depth(x + i, y + j) - mean) * (g.depth(x + i, y + j) - mean);
  return {double(n), double((long double)g.depth(x, y) - mean), double(var / n)};
}

TEST(Chebyshev, FixedWindowMomentsMatchBruteForceWithBackground) {
  Image depth = testing::random_image(37, 23, 7, 1.0f, 3.0f);
  for (int i = 0; i < 60; ++i) depth.pixels()[std::size_t(i) * 13 % depth.pixels().size()] = 1e10f;
  GBuffer g;
  g.depth = depth.view();
  g.camera = {30, 30, 18, 11};
  for (int r : {1, 4, 11, 30}) {
    ChebyshevSettings s;
    s.kernel_mode = 0;
    s.kernel_radius = r;
    s.shrink_at_background = false;  // background skipped, the rest counted
    const Image m = chebyshev_moments(g, s);
    for (int y = 0; y < g.height(); ++y)
      for (int x = 0; x < g.width(); ++x) {
        if (!g.valid(x, y)) {
          EXPECT_EQ(m(x, y, 0), 0.0f);
          continue;
        }
        const BruteMoments b = brute(g, x, y, r, r);
        ASSERT_EQ(m(x, y, 0), float(b.n)) << x << ',' << y;
        EXPECT_NEAR(m(x, y, 1), b.gap, 1e-5) << x << ',' << y << " r=" << r;
        EXPECT_NEAR(m(x, y, 2), b.variance, 1e-5) << x << ',' << y << " r=" << r;
      }
  }
}

TEST(Chebyshev, ShrunkWindowsHoldNoBackground) {
  Image depth = testing::random_image(41, 29, 3, 1.0f, 3.0f);
  for (int i = 0; i < 25; ++i) depth.pixels()[std::size_t(i) * 47 % depth.pixels().size()] = -1.0f;
  GBuffer g;
  g.depth = depth.view();
  g.camera = {30, 30, 20, 14};
  ChebyshevSettings s;
  s.kernel_mode = 0;
  s.kernel_radius = 6;
  const Image m = chebyshev_moments(g, s);
  for (int y = 0; y < g.height(); ++y)
    for (int x = 0; x < g.width(); ++x) {
      if (!g.valid(x, y)) continue;
      // The largest r <= 6 with no background within chessboard distance r.
      auto clear = [&](int r) {
        for (int j = std::max(0, y - r); j <= std::min(28, y + r); ++j)
          for (int i = std::max(0, x - r); i <= std::min(40, x + r); ++i)
            if (!g.valid(i, j)) return false;
        return true;
      };
      int r = 6;
      while (r > 0 && !clear(r)) --r;
      const BruteMoments b = r ? brute(g, x, y, r, r) : BruteMoments{1, 0, 0};
      ASSERT_EQ(m(x, y, 0), float(b.n)) << x << ',' << y;
      EXPECT_NEAR(m(x, y, 1), b.gap, 1e-5);
      EXPECT_NEAR(m(x, y, 2), b.variance, 1e-5);
    }
}

TEST(Chebyshev, AdaptiveWindowIsRfOverDQuantised) {
  SceneFixture f("blocks", 96, 54);
  ChebyshevSettings s;
  s.radius = 0.4f;
  const Image m = chebyshev_moments(f.g, s);
  for (int y = 0; y < 54; y += 5)
    for (int x = 0; x < 96; x += 3) {
      if (!f.g.valid(x, y)) continue;
      const int r = chebyshev_quantised_radius(double(s.radius) * f.g.camera.fx / f.g.depth(x, y),
                                               s.max_kernel_radius);
      const int rv = int(std::lround(double(r) * f.g.camera.fy / f.g.camera.fx));
      const BruteMoments b = r ? brute(f.g, x, y, r, rv) : BruteMoments{1, 0, 0};
      ASSERT_EQ(m(x, y, 0), float(b.n)) << x << ',' << y;
      EXPECT_NEAR(m(x, y, 1), b.gap, 1e-5 * (1 + std::abs(b.gap)));
      EXPECT_NEAR(m(x, y, 2), b.variance, 1e-5 * (1 + b.variance));
    }
}

TEST(Chebyshev, QuantisedRadius) {
  EXPECT_EQ(chebyshev_quantised_radius(0.49, 64), 0);
  EXPECT_EQ(chebyshev_quantised_radius(std::numeric_limits<double>::quiet_NaN(), 64), 0);
  EXPECT_EQ(chebyshev_quantised_radius(0.5, 64), 1);
  EXPECT_EQ(chebyshev_quantised_radius(7.6, 64), 8);
  EXPECT_EQ(chebyshev_quantised_radius(16.0, 64), 16);
  EXPECT_EQ(chebyshev_quantised_radius(32.0, 64), 32);
  EXPECT_EQ(chebyshev_quantised_radius(1e300, 64), 64);
  EXPECT_EQ(chebyshev_quantised_radius(1e300, 0), 0);
  EXPECT_EQ(chebyshev_quantised_radius(16.4, 64), 16);
  EXPECT_EQ(chebyshev_quantised_radius(20.0, 64), 19);
  EXPECT_EQ(chebyshev_quantised_radius(50.0, 40), 40);  // the cap need not be a level
  // Within ±10 % of r everywhere (integer steps to 16, then quarter octaves, rounded).
  for (double r = 0.5; r < 1000; r *= 1.01) {
    const int q = chebyshev_quantised_radius(r, 1024);
    EXPECT_LE(std::abs(q - r), r < 16.5 ? 0.5 : 0.1 * r) << r;
  }
  EXPECT_EQ(chebyshev_level_below(17), 16);
  EXPECT_EQ(chebyshev_level_below(22), 19);
  EXPECT_EQ(chebyshev_level_below(23), 23);
  EXPECT_EQ(chebyshev_level_below(5000), 1024);
}

// A plane facing the camera at depth 1.25·2^e with grooves 0-3 ulps deep (at 2^13 one ulp is
// 0.98 mm): the naive M2 − M1² in float cancels catastrophically there, ours stays exact.
Image relief_plane(int exponent) {
  Image depth(48, 32, 1);
  const float base = 1.25f, ulp = std::nextafter(base, 2.0f) - base;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 48; ++x)
      depth(x, y) = std::ldexp(base + float((x / 5) % 3 + (y / 7) % 2) * ulp, exponent);
  return depth;
}

TEST(Chebyshev, FarPlaneWithMillimetreReliefHasStableMoments) {
  ChebyshevSettings s;
  s.kernel_mode = 0;
  s.kernel_radius = 4;
  const Image near = relief_plane(0);
  GBuffer gn;
  gn.depth = near.view();
  gn.camera = {48, 48, 24, 16};
  const float ulp = std::nextafter(1.25f, 2.0f) - 1.25f;
  s.radius = 3 * ulp;
  const Image mn = chebyshev_moments(gn, s);
  const Image an = chebyshev(gn, s);
  for (int e : {13, 17}) {
    const Image far = relief_plane(e);
    GBuffer gf = gn;
    gf.depth = far.view();
    ChebyshevSettings sf = s;
    sf.radius = std::ldexp(s.radius, e);
    const Image mf = chebyshev_moments(gf, sf);
    const Image af = chebyshev(gf, sf);
    int naive_wrong = 0;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 48; ++x) {
        EXPECT_GE(mf(x, y, 2), 0.0f);
        // Exactly the near moments scaled: offsets scale exactly by powers of two.
        EXPECT_EQ(mf(x, y, 1), std::ldexp(mn(x, y, 1), e));
        EXPECT_EQ(mf(x, y, 2), std::ldexp(mn(x, y, 2), 2 * e));
        EXPECT_EQ(af(x, y), an(x, y));
        const BruteMoments b = brute(gf, x, y, 4, 4);
        EXPECT_NEAR(mf(x, y, 2), b.variance, 1e-3 * b.variance + 1e-30);
        // What M2 − M1² in float gives for the same window.
        const int rx = std::min({4, x, 47 - x}), ry = std::min({4, y, 31 - y});
        float m1 = 0, m2 = 0;
        for (int j = -ry; j <= ry; ++j)
          for (int i = -rx; i <= rx; ++i)
            m1 += far(x + i, y + j), m2 += far(x + i, y + j) * far(x + i, y + j);
        const float n = float((2 * rx + 1) * (2 * ry + 1));
        const float naive = m2 / n - (m1 / n) * (m1 / n);
        naive_wrong +=
            naive < 0.0f || std::abs(naive - float(b.variance)) > 0.5f * float(b.variance) + 1e-30f;
      }
    EXPECT_GT(naive_wrong, 100) << "the test scene must defeat the naive formula at 2^" << e;
  }
  float lowest = 1;
  for (float v : an.pixels()) lowest = std::min(lowest, v);
  EXPECT_LT(lowest, 0.9f);  // the relief is resolved
}

TEST(Chebyshev, VisibilityFormulas) {
  ChebyshevSettings s;
  s.radius = 1.0f;
  s.variance_bias = 0.0f;
  s.range_check = false;
  EXPECT_EQ(chebyshev_visibility(0.0f, 0.0f, s), 1.0f);   // §III-A: 0/0 → 1
  EXPECT_EQ(chebyshev_visibility(-1.0f, 0.0f, s), 1.0f);  // in front of the mean (eq. 3)
  EXPECT_FLOAT_EQ(chebyshev_visibility(0.5f, 0.25f, s), 0.5f);
  EXPECT_EQ(chebyshev_visibility(1.0f, 0.0f, s), 0.0f);
  s.ignore_unoccluded = false;
  EXPECT_FLOAT_EQ(chebyshev_visibility(-0.5f, 0.25f, s), 0.5f);  // eq. 2: both sides
  s.variance_bias = 1.0f;
  EXPECT_FLOAT_EQ(chebyshev_visibility(1.0f, 0.0f, s), 0.5f);  // ε = R²
  s.range_check = true;
  s.variance_bias = 0.0f;
  EXPECT_FLOAT_EQ(chebyshev_visibility(0.5f, 0.25f, s), 0.5f);  // gap within R: unchanged
  EXPECT_FLOAT_EQ(chebyshev_visibility(2.0f, 0.0f, s), 0.5f);   // smoothstep(1/2) = 1/2
}

}  // namespace
}  // namespace aolab
