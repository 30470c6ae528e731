// Line-sweep AO (Timonen 2013): the direction sets of §5.2, the open-plane values eq. 1
// implies, the obscure hull against brute force (§4.1), the gather, hard inputs. What every
// method promises (planes, background, threads, settings errors) is conformance_test's.
#include "core/methods/lsao/lsao.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "core/io/image_io.h"
#include "tests/cpp/test_support.h"
#include "tests/textbook/lsao_textbook.h"

namespace aolab {
namespace {

using testing::min_valid;
using testing::SceneFixture;

// The obscure hull with the cutoff falloff against brute force (160×90, R = 1): measured mean
// |ΔA| 5.5 % (wall), 3.3 % (crease), 2.1 % (blocks). Algorithm 1 pops a lower, nearer point
// under a higher, farther one, which is safe for eq. 2's falloff that never reaches zero but
// not for a hard cut-off: the farther point leaves R first (docs/methods/lsao.md).
constexpr double kCutoffHullMeanAbs = 0.07;

double mean_valid(const Image& ao, const GBuffer& g) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < ao.height(); ++y)
    for (int x = 0; x < ao.width(); ++x)
      if (g.valid(x, y)) sum += ao(x, y), ++n;
  return sum / n;
}

// ---- §5.2 direction sets ----

// Figure 10 and Table 2: the mean step of the aligned sets is 1.41 (K = 8), 2.43 (K = 16),
// 3.56 (K = 24), 4.69 (K = 32); the axis directions take that mean.
TEST(LsaoDirections, AlignedSetsHaveThePapersStepLengths) {
  const CameraIntrinsics cam{100, 100, 50, 50};
  const double expected[] = {1.41, 2.43, 3.56, 4.69};
  for (int n = 1; n <= 4; ++n) {
    const auto set = aligned_sweep_directions(n, 1, cam);
    ASSERT_EQ(int(set.size()), 8 * n);
    EXPECT_NEAR(mean_step_length(set), expected[n - 1], 0.005) << "n " << n;
    double weights = 0;
    for (const auto& d : set) {
      weights += d.weight;
      ASSERT_GE(d.opposite, 0);
      EXPECT_EQ(set[d.opposite].step_x, -d.step_x);
      EXPECT_EQ(set[d.opposite].step_y, -d.step_y);
      if (d.step_x == 0 || d.step_y == 0)
        EXPECT_NEAR(d.step_length(), mean_step_length(set), 1e-12);  // axis: the mean
      else
        EXPECT_TRUE(d.integer_step);
    }
    EXPECT_NEAR(weights, 1.0, 1e-12);
  }
  // Figure 1 and Figure 13 step two template vectors: 2.83 (K = 8) and 4.87 (K = 16).
  EXPECT_NEAR(mean_step_length(aligned_sweep_directions(1, 2, cam)), 2.83, 0.005);
  EXPECT_NEAR(mean_step_length(aligned_sweep_directions(2, 2, cam)), 4.87, 0.005);
}

// "Choosing sampling directions according to the box pattern causes directions near the
// diagonals to be sampled more densely ... smaller weights are given to the diagonal
// directions" (§5.2).
TEST(LsaoDirections, DiagonalsWeighLessThanAxes) {
  const auto set = aligned_sweep_directions(2, 1, CameraIntrinsics{100, 100, 50, 50});
  double diagonal = 0, axis = 0;
  for (const auto& d : set) {
    if (std::abs(d.step_x) == std::abs(d.step_y)) diagonal = d.weight;
    if (d.step_y == 0) axis = d.weight;
  }
  EXPECT_NEAR(diagonal, 2 * (std::atan(1.0) - std::atan(0.5)) / 2 / (2 * std::numbers::pi), 1e-12);
  EXPECT_NEAR(axis, 2 * std::atan(0.5) / 2 / (2 * std::numbers::pi), 1e-12);
  EXPECT_LT(diagonal, axis);
}

TEST(LsaoDirections, UniformSetsAreEvenAndPaired) {
  const CameraIntrinsics cam{100, 60, 50, 50};  // non-square pixels
  for (int k : {1, 2, 7, 12}) {
    const auto set = uniform_sweep_directions(k, 2.5, cam);
    for (int i = 0; i < k; ++i) {
      EXPECT_NEAR(set[i].weight, 1.0 / k, 1e-12);
      EXPECT_NEAR(set[i].step_length(), 2.5, 1e-12);
      EXPECT_NEAR(set[i].azimuth, 2 * std::numbers::pi * i / k, 1e-12);
      EXPECT_EQ(set[i].opposite, k % 2 == 0 ? (i + k / 2) % k : -1);
    }
  }
}

// ---- eq. 2 and eq. 3 ----

TEST(LsaoFalloff, EquationsTwoAndThree) {
  const float c = kLsaoFalloffOffset;
  // With r = C·R², eq. 3 reaches zero at d = R (q2 = 1/C) and eq. 2 halves at d = √C·R.
  EXPECT_NEAR(lsao_falloff(1.0f / c, LsaoFalloff::Eq3).rho, 0.0f, 1e-6f);
  EXPECT_EQ(lsao_falloff(1.01f / c, LsaoFalloff::Eq3).rho, 0.0f);
  EXPECT_EQ(lsao_falloff(1.01f / c, LsaoFalloff::Eq3).one_minus_rho, 1.0f);
  EXPECT_FLOAT_EQ(lsao_falloff(1.0f, LsaoFalloff::Eq2).rho, 0.5f);
  EXPECT_FLOAT_EQ(lsao_falloff(1.0f / c, LsaoFalloff::Eq2).rho, c / (1 + c));
  for (float q2 : {0.0f, 1e-8f, 0.1f, 1.0f, 3.0f, 1e6f}) {
    for (auto f : {LsaoFalloff::Eq2, LsaoFalloff::Eq3}) {
      const LsaoWeight w = lsao_falloff(q2, f);
      EXPECT_NEAR(w.rho + w.one_minus_rho, 1.0f, 1e-6f) << q2;
    }
    EXPECT_LE(lsao_falloff(q2, LsaoFalloff::Eq3).rho, lsao_falloff(q2, LsaoFalloff::Eq2).rho);
  }
  EXPECT_EQ(lsao_falloff(INFINITY, LsaoFalloff::Eq2).rho, 0.0f);
  EXPECT_EQ(lsao_falloff(0.0f, LsaoFalloff::Eq2).rho, 1.0f);
}

// The reference's hard cut-off: ρ = 1 up to d = R (q2 = d²/r = 1/C), 0 beyond, never between,
// and never below eq. 3 (which is ≤ 1 within R and 0 beyond).
TEST(LsaoFalloff, CutoffIsOneWithinRAndZeroBeyond) {
  const float c = kLsaoFalloffOffset;
  for (float q2 : {0.0f, 1e-8f, 0.1f, 1.0f, 3.0f, 0.999f / c}) {
    EXPECT_EQ(lsao_falloff(q2, LsaoFalloff::Cutoff).rho, 1.0f) << q2;
    EXPECT_EQ(lsao_falloff(q2, LsaoFalloff::Cutoff).one_minus_rho, 0.0f) << q2;
  }
  for (float q2 : {1.001f / c, 10.0f, 1e6f, float(INFINITY)}) {
    EXPECT_EQ(lsao_falloff(q2, LsaoFalloff::Cutoff).rho, 0.0f) << q2;
    EXPECT_EQ(lsao_falloff(q2, LsaoFalloff::Cutoff).one_minus_rho, 1.0f) << q2;
  }
  for (float q2 : {0.0f, 0.5f, 3.0f, 1.001f / c, 10.0f})
    EXPECT_GE(lsao_falloff(q2, LsaoFalloff::Cutoff).rho, lsao_falloff(q2, LsaoFalloff::Eq3).rho);
}

// ---- Open planes ----

LsaoSettings config(int index) {
  LsaoSettings s;
  switch (index) {
    case 1:
      s.template_size = 1, s.directions = 8;
      break;
    case 2:
      s.template_size = 3, s.directions = 24, s.line_spacing = 2.5f;
      break;
    case 3:
      s.template_stride = 2;
      break;
    case 4:
      s.template_size = 0, s.directions = 12, s.step = 1.0f, s.line_spacing = 1.0f;
      break;
    case 5:
      s.template_size = 0, s.directions = 8, s.step = 2.7f, s.sampling = 1;
      break;
    case 6:
      s.seed = 12345, s.falloff = 3;
      break;
    case 7:
      s.gather_depth_tolerance = 0.0f, s.normal_aware_gather = true;
      break;
    case 8:
      s.falloff = int(LsaoFalloff::Cutoff);
      break;
    default:
      break;
  }
  return s;
}

// A tilted plane at the centre pixel of an odd-sized image, which is sample 0 of line 0 of
// every direction: in direction k the largest occluder is the previous sample P − v_k (on a
// plane every earlier sample is at the same elevation s_k, and ρ falls with distance), so
// O_k = ρ(d_k) s_k + (1 − ρ(d_k)) sin t if s_k > sin t, else sin t, and A = 1 − Σ w_k O_k.
// Computed here in double from the plane's geometry.
double open_plane_answer(const SceneFixture& f, const LsaoSettings& s, int x, int y) {
  const LsaoPlan plan = lsao_plan(f.g, s);
  const CameraIntrinsics& cam = f.g.camera;
  auto pos = [&](double px, double py) {  // the snapped texel's centre and depth
    const int ix = int(std::floor(px)), iy = int(std::floor(py));
    const double d = f.g.depth(ix, iy), cx = ix + 0.5, cy = iy + 0.5;
    return glm::dvec3((cx - cam.cx) / cam.fx * d, -(cy - cam.cy) / cam.fy * d, -d);
  };
  const glm::dvec3 p = pos(x + 0.5, y + 0.5);
  double sum = 0;
  for (const auto& d : plan.directions) {
    const glm::dvec3 q = pos(x + 0.5 - d.step_x, y + 0.5 - d.step_y);
    const glm::dvec3 h = q - p;
    // Elevation from the zenith towards the eye: the plane through the eye, P and Q holds
    // both h and −P, so sin h is measured within it.
    const double sin_h = glm::dot(glm::normalize(h), glm::normalize(-p));
    const double q2 = glm::dot(h, h) / (double(kLsaoFalloffOffset) * s.radius * s.radius);
    const double rho = 1 / (1 + q2);
    const double sin_t = s.tangent_sin;
    sum += d.weight * (sin_h > sin_t ? rho * sin_h + (1 - rho) * sin_t : sin_t);
  }
  return std::clamp(1 - sum, 0.0, 1.0);
}

struct TiltCase {
  double tilt, azimuth, radius;
};

class LsaoTiltedPlane : public ::testing::TestWithParam<TiltCase> {};

TEST_P(LsaoTiltedPlane, MatchesEquationOneAtTheCentre) {
  const TiltCase c = GetParam();
  SceneFixture f("plane", 161, 91, {{"tilt", c.tilt}, {"azimuth", c.azimuth}});
  LsaoSettings s;
  s.radius = float(c.radius);
  const Image ao = lsao(f.g, s);
  EXPECT_NEAR(ao(80, 45), open_plane_answer(f, s, 80, 45), 2e-5);
}

INSTANTIATE_TEST_SUITE_P(Tilts, LsaoTiltedPlane,
                         ::testing::Values(TiltCase{0, 0, 1}, TiltCase{45, 30, 1},
                                           TiltCase{65, 0, 2}, TiltCase{70, 20, 0.5},
                                           TiltCase{80, 200, 1}, TiltCase{85, 90, 10},
                                           TiltCase{88, 45, 1e30}));

// Within the plane's slope limit (every |s_k| ≤ 0.85, i.e. tilts below asin 0.85 ≈ 58° near
// the centre) the plane is exactly unoccluded; steeper planes darken (§4.1: the fixed
// tangent counts the part of a steep slope below −0.85 as occluded with ρ = 1), never below
// (1 − sin t)/2 = 0.925.
TEST(Lsao, TiltedPlanesOneUntilTheFixedTangentThenBounded) {
  SceneFixture gentle("plane", 160, 90, {{"tilt", 40}, {"azimuth", 30}});
  EXPECT_EQ(min_valid(lsao(gentle.g, LsaoSettings{}), gentle.g), 1.0f);
  for (double tilt : {70.0, 85.0, 89.5}) {
    SceneFixture steep("plane", 128, 72, {{"tilt", tilt}});
    for (float radius : {1.0f, 1e30f}) {
      LsaoSettings s;
      s.radius = radius;
      const float m = min_valid(lsao(steep.g, s), steep.g);
      if (radius > 1.0f) {
        EXPECT_LT(m, 1.0f) << tilt;  // ρ = 1: every steep slice counts
      }
      EXPECT_GE(m, 0.925f) << tilt;
    }
  }
  // sin t = −1 (Figure 7's other end): no slope is steeper, every open plane is 1.
  SceneFixture grazing("plane", 128, 72, {{"tilt", 89.5}});
  LsaoSettings s;
  s.tangent_sin = -1.0f;
  EXPECT_EQ(min_valid(lsao(grazing.g, s), grazing.g), 1.0f);
}

// Strategies 1 and 2 use the real tangent: an open plane is unoccluded at any tilt up to the
// float rounding of its normal and the texel-centre geometry (the plane through a line's
// texel centres contains them exactly), with or without given normals.
TEST(Lsao, RealTangentStrategiesKeepTiltedPlanesOpen) {
  SceneFixture f("plane", 160, 90, {{"tilt", 75}, {"azimuth", 20}});
  GBuffer depth_only = f.g;
  depth_only.normal = {};
  for (int strategy : {1, 2}) {
    LsaoSettings s;
    s.tangent_strategy = strategy;
    EXPECT_GT(min_valid(lsao(f.g, s), f.g), 0.999f) << strategy;
    EXPECT_GT(min_valid(lsao(depth_only, s), f.g), 0.999f) << strategy;
  }
}

// ---- The obscure hull against brute force (§4.1) ----

struct HullStats {
  double mismatch_rate;  // share of geometry samples whose value differs by more than 1e-4
  double mean_abs;       // mean |A_hull − A_textbook| over geometry pixels
  double max_abs;
};

HullStats compare_with_textbook(const GBuffer& g, const LsaoSettings& s) {
  const LsaoSweep fast = lsao_sweep(g, s);
  const LsaoSweep slow = lsao_textbook_sweep(g, s);
  EXPECT_EQ(fast.buffer.size(), slow.buffer.size());
  std::size_t samples = 0, mismatches = 0;
  const LsaoPlan& plan = fast.plan;
  for (int k = 0; k < int(plan.directions.size()); ++k)
    for (std::size_t i = 0; i < plan.lines[plan.lines_of[k]].samples; ++i) {
      const float a = fast.value(k, i), b = slow.value(k, i);
      EXPECT_EQ(a == a, b == b) << k << " " << i;
      if (!(a == a)) continue;
      ++samples;
      if (std::abs(a - b) > 1e-4f) ++mismatches;
    }
  const Image ao_fast = lsao_gather(g, s, fast), ao_slow = lsao_gather(g, s, slow);
  double sum = 0, worst = 0;
  int n = 0;
  for (int y = 0; y < ao_fast.height(); ++y)
    for (int x = 0; x < ao_fast.width(); ++x)
      if (g.valid(x, y)) {
        const double d = std::abs(double(ao_fast(x, y)) - ao_slow(x, y));
        sum += d, worst = std::max(worst, d), ++n;
      }
  return {double(mismatches) / double(samples), sum / n, worst};
}

struct HullCase {
  const char* scene;
  float radius;
  int strategy;
};

class LsaoHull : public ::testing::TestWithParam<HullCase> {};

// Acceptance: with the paper's fixed tangent (strategy 3) the hull's degenerate cases cost
// under 0.5 % of AO on average (the paper measured 0.02–0.3 %), and at most a few percent of
// the samples see a smaller occluder than the largest one. Strategy 1 pops with each
// receiver's own tangent, which "will cause the obscure hull to rapidly unfold when the
// tangent becomes steep ... future largest occluders being culled" (§4.1): more misses,
// bounded looser. The measured numbers are printed for docs/methods/lsao.md.
TEST_P(LsaoHull, MatchesBruteForceExceptRareDegenerateCases) {
  const HullCase c = GetParam();
  SceneFixture f(c.scene, 256, 144);
  LsaoSettings s;
  s.radius = c.radius;
  s.tangent_strategy = c.strategy;
  const HullStats h = compare_with_textbook(f.g, s);
  std::cout << "[hull] " << c.scene << " R " << c.radius << " strategy " << c.strategy
            << ": samples differing " << 100 * h.mismatch_rate << " %, mean |dA| "
            << 100 * h.mean_abs << " %, max |dA| " << h.max_abs << "\n";
  const bool paper = c.strategy == 3;
  EXPECT_LT(h.mean_abs, paper ? 0.005 : 0.01);
  EXPECT_LT(h.mismatch_rate, paper ? 0.05 : 0.15);
}

INSTANTIATE_TEST_SUITE_P(Scenes, LsaoHull,
                         ::testing::Values(HullCase{"blocks", 0.25f, 3},
                                           HullCase{"blocks", 1.0f, 3}, HullCase{"blocks", 2.0f, 3},
                                           HullCase{"wall", 1.0f, 3}, HullCase{"crease", 1.0f, 3},
                                           HullCase{"step", 1.0f, 3}, HullCase{"blocks", 1.0f, 1},
                                           HullCase{"blocks", 1.0f, 2}, HullCase{"wall", 1.0f, 1}));

// hull_search only adds candidates for the written value: per sample it is never below
// Algorithm 1's and never above brute force's (both pick by the same criterion), and with the
// whole stack searched only occluders popped earlier (§4.1's example) are still missed.
TEST(Lsao, HullSearchLiesBetweenAlgorithmOneAndBruteForce) {
  SceneFixture f("blocks", 128, 72);
  LsaoSettings s;
  s.radius = 2.0f;
  const LsaoSweep paper = lsao_sweep(f.g, s), slow = lsao_textbook_sweep(f.g, s);
  for (int search : {4, 256}) {
    s.hull_search = search;
    const LsaoSweep fast = lsao_sweep(f.g, s);
    int below = 0, above = 0, far = 0, total = 0;
    for (int k = 0; k < int(fast.plan.directions.size()); ++k)
      for (std::size_t i = 0; i < fast.plan.lines[fast.plan.lines_of[k]].samples; ++i) {
        const float a = fast.value(k, i), p = paper.value(k, i), b = slow.value(k, i);
        if (!(a == a)) continue;
        below += a < p - 1e-6f;
        above += a > b + 1e-4f;
        far += std::abs(a - b) > 1e-4f;
        ++total;
      }
    std::cout << "[hull_search " << search << "] " << far << " of " << total
              << " samples differ from brute force\n";
    EXPECT_EQ(below, 0) << search;
    EXPECT_EQ(above, 0) << search;
    if (search == 256) {
      EXPECT_LT(far, total / 200);
    }
  }
}

TEST(Lsao, HullMatchesBruteForceInOtherLayouts) {
  SceneFixture f("blocks", 160, 90);
  for (int i : {1, 4, 5, 6}) {
    LsaoSettings s = config(i);
    s.radius = 1.0f;
    const HullStats h = compare_with_textbook(f.g, s);
    EXPECT_LT(h.mean_abs, 0.005) << "config " << i;
  }
}

// ---- The gather (§5.1) ----

TEST(Lsao, GatherPicksTheNearestPassingValueOfEveryDirection) {
  SceneFixture f("blocks", 64, 36);
  for (int i : {0, 4, 5, 7}) {
    const LsaoSettings s = config(i);
    const LsaoSweep sweep = lsao_sweep(f.g, s);
    const Image fast = lsao_gather(f.g, s, sweep), slow = lsao_textbook_gather(f.g, s, sweep);
    int differ = 0;
    for (std::size_t p = 0; p < fast.pixels().size(); ++p)
      if (std::abs(fast.pixels()[p] - slow.pixels()[p]) > 1e-6f) ++differ;
    EXPECT_EQ(differ, 0) << "config " << i;
  }
}

// §5.2: "an intermediate floating point buffer the size of K·W·H/(D_S·D_L) elements".
TEST(Lsao, IntermediateBufferHoldsKWHOverDsDl) {
  SceneFixture f("plane", 640, 360);
  for (int i : {0, 2, 3, 4, 5}) {
    const LsaoSettings s = config(i);
    const LsaoPlan plan = lsao_plan(f.g, s);
    const double ds = mean_step_length(plan.directions);
    const double expected = double(plan.directions.size()) * 640 * 360 / (ds * s.line_spacing);
    EXPECT_NEAR(double(plan.value_count) / expected, 1.0, 0.03) << "config " << i;
  }
}

// ---- Determinism, hard inputs, errors ----

TEST(Lsao, OcclusionGrowsWithRadiusAndEq3IsLighter) {
  SceneFixture f("crease", 160, 90);
  double previous = 1.0;
  for (float radius : {0.5f, 1.0f, 2.0f, 4.0f}) {
    LsaoSettings eq2, eq3;
    eq2.radius = eq3.radius = radius;
    eq3.falloff = 3;
    const double m2 = mean_valid(lsao(f.g, eq2), f.g), m3 = mean_valid(lsao(f.g, eq3), f.g);
    EXPECT_LT(m2, previous) << radius;
    EXPECT_GT(m3, m2) << radius;  // ρ0 ≤ ρ everywhere
    previous = m2;
  }
  // Per sample, by brute force: the largest weighted occluder can only lose weight.
  LsaoSettings eq2, eq3;
  eq3.falloff = 3;
  const LsaoSweep a = lsao_textbook_sweep(f.g, eq2), b = lsao_textbook_sweep(f.g, eq3);
  for (std::size_t i = 0; i < a.buffer.size(); ++i)  // depths are equal, values can only drop
    if (a.buffer[i] == a.buffer[i]) {
      ASSERT_LE(b.buffer[i], a.buffer[i] + 1e-6f) << i;
    }
}

// The cutoff falloff (ρ = 1 within R, 0 beyond, the reference's) against the brute-force
// textbook version, per sample never lighter than eq. 3 (ρ0 ≤ 1 within R, 0 beyond, so the largest
// weighted occluder can only gain weight), and on the scenes with a closed form
// (cycles_ao_beside_wall) closer to Cycles than the paper's eq. 2: measured MAE 0.041 against
// 0.089 (wall), 0.022 against 0.075 (crease).
TEST(Lsao, CutoffMatchesBruteForceAndIsDarkerThanEq3) {
  for (const char* scene : {"wall", "crease", "blocks"}) {
    SceneFixture f(scene, 160, 90);
    LsaoSettings cutoff, eq3, eq2;
    cutoff.falloff = int(LsaoFalloff::Cutoff);
    eq3.falloff = int(LsaoFalloff::Eq3);
    if (std::string(scene) != "blocks") {
      const double e2 = testing::mae_against_reference(lsao(f.g, eq2), f);
      const double ec = testing::mae_against_reference(lsao(f.g, cutoff), f);
      std::cout << "[cutoff] " << scene << " MAE eq. 2 " << e2 << ", cutoff " << ec << "\n";
      EXPECT_LT(ec, 0.6 * e2) << scene;
    }
    const HullStats h = compare_with_textbook(f.g, cutoff);
    std::cout << "[hull] cutoff " << scene << ": samples differing " << 100 * h.mismatch_rate
              << " %, mean |dA| " << 100 * h.mean_abs << " %, max |dA| " << h.max_abs << "\n";
    EXPECT_LT(h.mean_abs, kCutoffHullMeanAbs) << scene;
    const LsaoSweep a = lsao_textbook_sweep(f.g, eq3), b = lsao_textbook_sweep(f.g, cutoff);
    for (std::size_t i = 0; i < a.buffer.size(); ++i)
      if (a.buffer[i] == a.buffer[i]) {
        ASSERT_GE(b.buffer[i], a.buffer[i] - 1e-6f) << scene << " " << i;
      }
  }
}

TEST(Lsao, RadiusBelowAPixelIsOne) {
  SceneFixture f("blocks", 96, 54);
  LsaoSettings s;
  s.radius = 1e-4f;
  EXPECT_EQ(min_valid(lsao(f.g, s), f.g), 1.0f);
}

// Beyond the ranges of the settings table (conformance_test): K must match the template.
TEST(Lsao, RejectsDirectionsThatDoNotMatchTheTemplate) {
  SceneFixture f("plane", 8, 8);
  LsaoSettings s;
  s.directions = 8;  // template_size 2 needs 16
  const std::string message = testing::invalid_argument_message([&] { lsao(f.g, s); });
  EXPECT_NE(message.find("directions must be 8 x template_size = 16"), std::string::npos)
      << message;
}

TEST(Lsao, RegistryNeedsDepthOnly) {
  SceneFixture f("blocks", 64, 36);
  GBuffer g = f.g;
  g.normal = {};
  const Method& m = find_method("lsao");
  EXPECT_FALSE(m.needs_normal);
  const Image a = compute("lsao", g, {{"radius", 0.5}});
  const Image b = compute("lsao", f.g, {{"radius", 0.5}});
  EXPECT_EQ(a.pixels(), b.pixels());  // strategy 3 does not read normals
  // A strategy that does read them estimates them from depth when there are none.
  const Image c = compute("lsao", g, {{"radius", 0.5}, {"tangent_strategy", 1}});
  const Image d = compute("lsao", f.g, {{"radius", 0.5}, {"tangent_strategy", 1}});
  EXPECT_LT(std::abs(mean_valid(c, f.g) - mean_valid(d, f.g)), 0.01);
}

// The same acceptance on the committed Cycles reference scenes (their real G-buffers, at
// each scene's R). The brute-force textbook version walks every earlier sample of a line for each
// receiver (quadratic in the line length), so each scene is cropped to its central 320x180:
// the crop is a G-buffer of its own (principal point shifted).
struct ReferenceCrop {
  const char* scene;
  int x0, y0;  // top-left of the 320×180 tile compared
};

class LsaoHullOnReferences : public ::testing::TestWithParam<ReferenceCrop> {};

// The hull's accuracy bound (mean |ΔA| < 0.5 % against brute force, docs/methods/lsao.md) on
// the committed reference G-buffers, at each scene's R. Measured there: with Algorithm 1
// exactly (hull_search = 0) the mean |ΔA| is 0.07–0.21 % everywhere but `grille`, 4.49 %:
// there the largest occluder of a wall receiver is a wall point still on the stack, under the
// last bar point, which is higher but farther in view space, and line 12's "and below it"
// stops the popping at the bar. An independent re-implementation of the pseudocode
// (docs/methods/lsao.md) gives the same rate, so this is the algorithm, not this code;
// hull_search = 16 brings every scene under 0.5 %.
TEST_P(LsaoHullOnReferences, MatchesBruteForce) {
  const ReferenceCrop crop = GetParam();
  const std::string name = crop.scene;
  const GBufferData data =
      load_gbuffer(std::string(AOLAB_SOURCE_DIR) + "/reference_scenes/" + name + "/reference.exr");
  GBuffer g = data.view();
  const int w = 320, h = 180;
  auto cut = [&](ConstImageView v) {
    if (v.empty()) return v;
    return ConstImageView(&v(crop.x0, crop.y0), w, h, v.channels, v.row_stride);
  };
  g.depth = cut(g.depth);
  g.normal = cut(g.normal);
  g.color = cut(g.color);
  g.emission = cut(g.emission);
  g.camera.cx -= float(crop.x0);
  g.camera.cy -= float(crop.y0);
  for (int search : {0, 16}) {
    LsaoSettings s;
    s.radius = float(data.sidecar.ao_distance);
    s.hull_search = search;
    const HullStats hs = compare_with_textbook(g, s);
    std::cout << "[hull] reference " << name << " R " << s.radius << " hull_search " << search
              << ": samples differing " << 100 * hs.mismatch_rate << " %, mean |dA| "
              << 100 * hs.mean_abs << " %, max |dA| " << hs.max_abs << "\n";
    // The grille bound with Algorithm 1 only guards against it getting worse (see above).
    EXPECT_LT(hs.mean_abs, search == 0 && name == "grille" ? 0.05 : 0.005) << search;
  }
}

// The tiles are the image centre, except `street`, whose centre is distant facades where
// R = 0.3 m covers less than a pixel and every A clamps to 1 (the hull values differ there
// with no effect); its lower right has the kerbs and the near buildings.
INSTANTIATE_TEST_SUITE_P(
    Scenes, LsaoHullOnReferences,
    ::testing::Values(ReferenceCrop{"analytic", 480, 270}, ReferenceCrop{"room", 480, 270},
                      ReferenceCrop{"engine", 480, 270}, ReferenceCrop{"grille", 480, 270},
                      ReferenceCrop{"street", 960, 360}, ReferenceCrop{"colored_room", 480, 270}),
    [](const auto& test) { return std::string(test.param.scene); });

}  // namespace
}  // namespace aolab
