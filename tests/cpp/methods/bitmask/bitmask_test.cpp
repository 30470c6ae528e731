// Known answers for the visibility bitmask (Therrien, Levesque, Gilet 2023): with an unbounded
// thickness and cosine weights it is GTAO's horizon result up to the sector quantisation, on
// either side by rounding; the closed forms of wall, crease and (with the sphere clip, which
// GTAO lacks) ceiling; a thin occluder lets light pass behind it; the orderings the settings
// promise; large thicknesses and radii. What every method promises (planes, background,
// threads, settings errors) is conformance_test's.
#include "core/methods/bitmask/bitmask.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/methods/gtao/gtao.h"
#include "tests/cpp/methods/vao/convex_room.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::closed_form_errors;
using testing::ClosedFormErrors;
using testing::expect_other_noise_same_mean;
using testing::SceneFixture;

// Tolerances of the closed-form tests, about twice the measured errors (docs/methods/bitmask.md).
constexpr double kClosedFormMean = 0.008, kClosedFormWorst = 0.05;

// The exact cosine-weighted form with a height field: what GTAO computes, in sectors.
BitmaskSettings height_field(float radius) {
  BitmaskSettings s;
  s.radius = radius;
  s.weighting = int(BitmaskWeighting::Cosine);
  s.radius_clip = int(BitmaskRadiusClip::Cut);
  s.thickness = kBitmaskUnboundedThickness;
  return s;
}

double mean_abs_diff(const Image& a, const Image& b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.pixels().size(); ++i)
    sum += std::abs(double(a.pixels()[i]) - b.pixels()[i]);
  return sum / double(a.pixels().size());
}

// With an unbounded thickness every sample marks its sectors from its direction to the
// tangent, so the free sectors are those above the highest sample: GTAO's horizon, with the
// same samples (same slices, steps and random streams). Touch rounds that horizon outwards
// (darker), cover inwards (lighter); the gap is at most one sector per side and shrinks as
// the sectors get finer.
TEST(Bitmask, UnboundedThicknessBracketsGtao) {
  SceneFixture f("blocks", 160, 90);
  GtaoSettings g;
  g.radius = 0.5f;
  g.slices = 4;
  g.steps = 8;
  const Image gtao_ao = gtao(f.g, g);
  double gap[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    BitmaskSettings s = height_field(0.5f);
    s.slices = g.slices;
    s.steps = g.steps;
    s.sectors = k == 0 ? 32 : 64;
    s.rounding = int(BitmaskRounding::Touch);
    const Image touch = bitmask(f.g, s);
    s.rounding = int(BitmaskRounding::Cover);
    const Image cover = bitmask(f.g, s);
    for (std::size_t i = 0; i < gtao_ao.pixels().size(); ++i) {
      ASSERT_LE(touch.pixels()[i], gtao_ao.pixels()[i] + 1e-5f) << i << " sectors " << s.sectors;
      ASSERT_GE(cover.pixels()[i], gtao_ao.pixels()[i] - 1e-5f) << i << " sectors " << s.sectors;
    }
    gap[k] = mean_abs_diff(touch, cover);
  }
  EXPECT_LT(gap[0], 0.06);
  EXPECT_LT(gap[1], 0.6 * gap[0]);  // halving the sector width about halves the bracket
}

BitmaskSettings exact_settings(float radius) {
  BitmaskSettings s = height_field(radius);
  s.radius_clip = int(BitmaskRadiusClip::Sphere);
  s.back_direction = int(BitmaskBackDirection::SampleRay);
  s.slices = 16;
  s.steps = 32;
  s.sectors = 64;
  s.rounding = int(BitmaskRounding::Half);
  s.random_rotation = s.jitter = false;
  return s;
}

// Cosine weights, an unbounded thickness along each sample's own view ray and the sphere clip:
// a direction counts as occluded where it meets the solid behind a visible surface within R,
// which is Cycles' definition on a depth buffer. That holds on `wall` and `crease` (as for
// GTAO; measured MAE 0.0041 and 0.0034, worst 0.024 and 0.016).
TEST(Bitmask, WallAndCreaseMatchTheClosedForm) {
  for (const char* scene : {"wall", "crease"}) {
    SceneFixture f(scene, 320, 180, {{"radius", 1.0}});
    const ClosedFormErrors e = closed_form_errors(f, bitmask(f.g, exact_settings(1.0f)), 40);
    ASSERT_GT(e.pixels, 10000);
    EXPECT_LT(e.mean, kClosedFormMean) << scene;
    EXPECT_LT(e.worst, kClosedFormWorst) << scene;
  }
}

// Under the overhang of `ceiling` the occluded directions are a cone of half-angle acos(h/R),
// which the clipped segments reproduce and GTAO's horizon cannot (it takes the whole band
// below the ceiling's horizon). Where the cone lies within the projected radius on screen
// (depth between 2R + 1 and 12, 40 px from the sides) measured MAE 0.017 (R = 1.25) and
// 0.0063 (R = 2), worst 0.048 and 0.031, against GTAO's 0.093 and 0.047. Nearer the camera
// the ceiling within R lies beyond the projected radius (lighter), near the horizon the
// samples collapse onto a few texels.
TEST(Bitmask, CeilingMatchesTheClosedFormWhereGtaoCannot) {
  for (float radius : {1.25f, 2.0f}) {
    SceneFixture f("ceiling", 320, 180, {{"radius", radius}});
    const Image ao = bitmask(f.g, exact_settings(radius));
    GtaoSettings gs;
    gs.radius = radius;
    gs.slices = 16;
    gs.steps = 32;
    gs.random_rotation = gs.jitter = false;
    const Image gt = gtao(f.g, gs);
    double mean = 0.0, worst = 0.0, gtao_mean = 0.0;
    int pixels = 0;
    for (int y = 0; y < ao.height(); ++y)
      for (int x = 40; x < ao.width() - 40; ++x) {
        const float d = f.scene.depth(x, y), ref = f.scene.reference(x, y);
        if (!(d > 2.0f * radius + 1.0f && d < 12.0f) || !std::isfinite(ref)) continue;
        const double err = std::abs(double(ao(x, y)) - ref);
        mean += err, worst = std::max(worst, err), ++pixels;
        gtao_mean += std::abs(double(gt(x, y)) - ref);
      }
    ASSERT_GT(pixels, 2000);
    mean /= pixels, gtao_mean /= pixels;
    EXPECT_LT(mean, 0.035) << radius;
    EXPECT_LT(worst, 0.1) << radius;
    EXPECT_LT(mean, 0.5 * gtao_mean) << radius;
  }
}

// A floor facing the camera at depth 5 and a thin horizontal bar 1 unit in front of it: as a
// height field the bar shadows every direction from itself down to the floor's tangent; with
// a thin thickness only the directions that meet the bar, so the floor beside it is brighter.
TEST(Bitmask, ThinOccluderLetsLightPassBehind) {
  const int w = 160, h = 90;
  Image depth(w, h, 1, 5.0f), normal(w, h, 3, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      normal(x, y, 2) = 1.0f;
      if (y >= 40 && y < 43) depth(x, y) = 4.0f;
    }
  GBuffer g;
  g.depth = depth.view();
  g.normal = normal.view();
  g.camera = {100.0f, 100.0f, 80.0f, 45.0f};
  BitmaskSettings thick = height_field(2.0f);
  thick.radius_clip = int(BitmaskRadiusClip::None);
  thick.steps = 32;
  BitmaskSettings thin = thick;
  thin.thickness = 0.05f;
  const Image a = bitmask(g, thick), b = bitmask(g, thin);
  // The floor a few rows below the bar.
  double dark = 0.0, light = 0.0;
  for (int y = 46; y < 52; ++y)
    for (int x = 40; x < 120; ++x) dark += a(x, y), light += b(x, y);
  dark /= 6 * 80, light /= 6 * 80;
  EXPECT_LT(dark, 0.85);
  EXPECT_GT(light, dark + 0.05);
  for (std::size_t i = 0; i < a.pixels().size(); ++i)
    ASSERT_GE(b.pixels()[i], a.pixels()[i]) << i;  // a thinner occluder marks fewer sectors
}

// Each sample's marked sectors nest: touch ⊇ half ⊇ cover, and a thicker surface marks a
// superset; so per pixel visibility is ordered exactly.
TEST(Bitmask, RoundingAndThicknessOrderTheResult) {
  SceneFixture f("blocks", 160, 90);
  for (int weighting : {0, 1}) {
    BitmaskSettings s;
    s.radius = 0.5f;
    s.weighting = weighting;
    std::vector<Image> by_rounding;
    for (int r : {0, 1, 2}) {
      s.rounding = r;
      by_rounding.push_back(bitmask(f.g, s));
    }
    s.rounding = 0;
    std::vector<Image> by_thickness;
    for (float t : {0.0f, 0.1f, 0.5f, 2.0f, kBitmaskUnboundedThickness}) {
      s.thickness = t;
      by_thickness.push_back(bitmask(f.g, s));
    }
    for (std::size_t i = 0; i < by_rounding[0].pixels().size(); ++i) {
      ASSERT_LE(by_rounding[0].pixels()[i], by_rounding[1].pixels()[i]) << i;
      ASSERT_LE(by_rounding[1].pixels()[i], by_rounding[2].pixels()[i]) << i;
      for (std::size_t k = 1; k < by_thickness.size(); ++k)
        ASSERT_LE(by_thickness[k].pixels()[i], by_thickness[k - 1].pixels()[i]) << i << " " << k;
    }
    EXPECT_GT(mean_abs_diff(by_thickness[1], by_thickness[4]), 0.01);
  }
}

// The paper's uniform count and the cosine weights agree where every sector is free or every
// one taken, and differ in between: the uniform count weighs grazing sectors as much as those
// along the normal.
TEST(Bitmask, UniformAndCosineWeightsDiffer) {
  SceneFixture f("blocks", 160, 90);
  BitmaskSettings u;
  u.radius = 0.5f;
  BitmaskSettings c = u;
  c.weighting = int(BitmaskWeighting::Cosine);
  EXPECT_GT(mean_abs_diff(bitmask(f.g, u), bitmask(f.g, c)), 0.005);
}

// T = thickness·R and its square are formed in double: thicknesses far beyond the scene all
// mean "unbounded" and give the same bits, up to the largest accepted value (T = 1e30·R).
TEST(Bitmask, HugeThicknessesAreTheHeightField) {
  SceneFixture f("blocks", 160, 90);
  for (int clip : {0, 1, 2}) {
    BitmaskSettings s;
    s.radius = 0.5f;
    s.radius_clip = clip;
    s.thickness = 1e4f;
    const Image ref = bitmask(f.g, s);
    for (float t : {1e8f, 1e15f, 1e20f, 1e30f}) {
      s.thickness = t;
      EXPECT_EQ(bitmask(f.g, s).pixels(), ref.pixels()) << "thickness " << t << " clip " << clip;
    }
  }
}

// Beyond the scene's extent the first sample of every slice already lies past the image
// border (without jitter; with it a pixel whose w is within R's reciprocal of 1 keeps a
// sample on screen, as for GTAO), so the result is 1 and stays 1 up to R = 1e30 (R² = 1e60 and T up
// to 1e60 in double).
TEST(Bitmask, LargeRadiiBeyondTheSceneGiveTheSameAo) {
  testing::ConvexRoom room;
  for (int clip : {0, 1, 2})
    for (float thickness : {0.5f, kBitmaskUnboundedThickness}) {
      BitmaskSettings s;
      s.radius_clip = clip;
      s.thickness = thickness;
      s.jitter = false;  // the first sample at a whole step: past the border for every pixel
      s.radius = 8e6f;
      const Image ref = bitmask(room.g, s);
      for (float radius : {1e12f, 1e19f, 1e20f, 1e25f, 1e30f}) {
        s.radius = radius;
        const Image ao = bitmask(room.g, s);
        EXPECT_EQ(ao.pixels(), ref.pixels()) << "R " << radius << " clip " << clip;
      }
      EXPECT_EQ(testing::min_valid(ref, room.g), 1.0f);
    }
}

// Another seed, and far samples on the depth MIP chain (q = 4 px), change the noise, not the
// mean.
TEST(Bitmask, SeedChangesNoiseButNotMean) {
  SceneFixture f("blocks", 200, 120);
  BitmaskSettings s0, s1, s2;
  s0.radius = s1.radius = s2.radius = 0.5f;
  s1.seed = 7;
  s2.mip_distance = 4.0f;
  const Image base = bitmask(f.g, s0);
  expect_other_noise_same_mean(base, bitmask(f.g, s1), 3e-3);
  expect_other_noise_same_mean(base, bitmask(f.g, s2), 3e-3);
}

// The chain's samples are real pixels with their exact depths: open planes stay 1.
TEST(Bitmask, MipChainKeepsOpenPlanesExactlyUnoccluded) {
  for (float tilt : {0.0f, 60.0f}) {
    SceneFixture f("plane", 203, 117, {{"tilt", tilt}});
    BitmaskSettings s;
    s.radius = 2.0f, s.steps = 16, s.mip_distance = 1.0f;
    EXPECT_EQ(testing::min_valid(bitmask(f.g, s), f.g), 1.0f) << "tilt " << tilt;
  }
}

}  // namespace
}  // namespace aolab
