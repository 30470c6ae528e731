// The analytic scenes are exact: check them against their own geometry and against the
// Cycles closed forms measured in docs/blender_facts.md, "The Cycles AO pass".
#include "core/scenes/analytic_scenes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>

namespace aolab {
namespace {

TEST(CyclesClosedForms, MatchMeasuredValues) {
  // Measured in Cycles (docs/blender_facts.md): ceiling at h = 1: 0.64 at R = 1.25, 0.25 at
  // R = 2, 0.0625 at R = 4.
  EXPECT_NEAR(cycles_ao_under_ceiling(1, 1.25), 0.64, 1e-12);
  EXPECT_NEAR(cycles_ao_under_ceiling(1, 2), 0.25, 1e-12);
  EXPECT_NEAR(cycles_ao_under_ceiling(1, 4), 0.0625, 1e-12);
  EXPECT_EQ(cycles_ao_under_ceiling(1, 0.5), 1.0);
  EXPECT_NEAR(cycles_ao_beside_wall(0, 2), 0.5, 1e-12);  // on the crease
  EXPECT_EQ(cycles_ao_beside_wall(2, 2), 1.0);
  EXPECT_LT(cycles_ao_beside_wall(0.5, 2), cycles_ao_beside_wall(1.0, 2));
}

TEST(AnalyticScene, FacingPlaneHasConstantDepth) {
  const auto s = analytic_scene("plane", 64, 36, {{"distance", 5}, {"fov", 122}});
  for (float d : s.depth.pixels()) EXPECT_NEAR(d, 5.0f, 5e-6f);  // planar depth, corners too
  for (int y = 0; y < 36; ++y)
    for (int x = 0; x < 64; ++x) EXPECT_FLOAT_EQ(s.normal(x, y, 2), 1.0f);
}

TEST(AnalyticScene, ReconstructedPointsLieOnTheirPlane) {
  const auto s = analytic_scene("plane", 80, 60, {{"distance", 3}, {"tilt", 70}, {"azimuth", 20}});
  const double t = 70 * M_PI / 180, a = 20 * M_PI / 180;
  const glm::dvec3 n(std::sin(t) * std::sin(a), std::sin(t) * std::cos(a), std::cos(t));
  int hits = 0;
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 80; ++x) {
      const float d = s.depth(x, y);
      if (d >= kAnalyticBackgroundDepth) continue;
      ++hits;
      const glm::dvec3 p(s.camera.view_position(float(x) + 0.5f, float(y) + 0.5f, d));
      EXPECT_NEAR(glm::dot(n, p - glm::dvec3(0, 0, -3)), 0.0, 1e-5 * d);
    }
  EXPECT_GT(hits, 1000);
}

TEST(AnalyticScene, CeilingReferenceFollowsRadius) {
  const auto s = analytic_scene("ceiling", 32, 32, {{"ceiling_height", 1}, {"radius", 2}});
  for (float v : s.reference.pixels()) EXPECT_NEAR(v, 0.25f, 1e-7f);
}

TEST(AnalyticScene, UnknownNameOrParameterIsAnError) {
  EXPECT_THROW(analytic_scene("nope", 8, 8), std::invalid_argument);
  EXPECT_THROW(analytic_scene("plane", 8, 8, {{"bogus", 1}}), std::invalid_argument);
  EXPECT_THROW(analytic_scene("plane", 0, 8), std::invalid_argument);
  EXPECT_THROW(analytic_scene("plane", 8, 8, {{"tilt", 90}}), std::invalid_argument);
  EXPECT_THROW(analytic_scene("blocks", 8, 8, {{"size", 0}}), std::invalid_argument);
  EXPECT_THROW(analytic_scene("wall", 8, 8, {{"camera_height", -1}}), std::invalid_argument);
  EXPECT_THROW(analytic_scene("crease", 8, 8, {{"fov", 180}}), std::invalid_argument);
}

}  // namespace
}  // namespace aolab
