// A convex room around the camera for the VAO and VAO++ tests of very large radii. Unlike the
// analytic scenes, one of its walls turns away from the view axis (its view-space normal has
// n.z < 0): only there does VAO's tangent sphere stay in front of the camera as R grows, so
// only there does a precision loss at large R show (the analytic scenes give exactly 1).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <limits>
#include <string>

#include "core/base/gbuffer.h"
#include "core/base/image.h"

namespace aolab::testing {

struct ConvexRoom {
  Image depth, normal;
  GBuffer g;

  // Planes n·X >= c (n pointing into the room, the camera at the origin inside it): a left
  // wall turned away from the view axis, floor, right wall, ceiling, back wall. Depths 1.5 to
  // 8; every pixel sees a wall, and the corners between them occlude.
  ConvexRoom(int width = 96, int height = 54, double fov_deg = 100.0)
      : depth(width, height, 1), normal(width, height, 3) {
    struct Plane {
      glm::dvec3 n;
      double c;
    };
    const Plane planes[] = {{glm::normalize(glm::dvec3(1.0, 0.0, -0.5)), -1.5},
                            {{0.0, 1.0, 0.0}, -1.0},
                            {{-1.0, 0.0, 0.0}, -2.0},
                            {{0.0, -1.0, 0.0}, -1.5},
                            {{0.0, 0.0, 1.0}, -8.0}};
    const double f = 0.5 * width / std::tan(0.5 * fov_deg * 3.14159265358979323846 / 180.0);
    g.camera = {float(f), float(f), 0.5f * float(width), 0.5f * float(height)};
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const glm::dvec3 v((x + 0.5 - 0.5 * width) / f, -(y + 0.5 - 0.5 * height) / f, -1.0);
        double best = std::numeric_limits<double>::infinity();
        glm::dvec3 best_n(0.0);
        for (const Plane& p : planes) {
          const double nv = glm::dot(p.n, v);
          if (nv < 0.0 && p.c / nv < best) best = p.c / nv, best_n = p.n;
        }
        depth(x, y) = float(best);  // v.z = -1: the ray parameter is planar depth
        for (int k = 0; k < 3; ++k) normal(x, y, k) = float(best_n[k]);
      }
    g.depth = depth.view();
    g.normal = normal.view();
  }
};

/// The mean of a 1-channel image over the G-buffer's geometry pixels.
inline double mean_over_geometry(const Image& ao, const GBuffer& g) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < ao.height(); ++y)
    for (int x = 0; x < ao.width(); ++x)
      if (g.valid(x, y)) sum += ao(x, y), ++n;
  return n ? sum / n : 1.0;
}

/// Beyond the scene's extent a larger R cannot change the occlusion: `ao_at(radius)` at
/// R = 1e6 times the deepest wall (where it must show some occlusion, a mean below
/// `occluded_below`) and at radii up to the accepted maximum 1e30 give the same mean AO.
template <class F>
void expect_large_radii_agree(const ConvexRoom& room, F&& ao_at, double occluded_below,
                              const std::string& label) {
  const double at_scale = mean_over_geometry(ao_at(8e6f), room.g);
  EXPECT_LT(at_scale, occluded_below) << "the turned-away wall must see occlusion; " << label;
  for (float radius : {1e12f, 1e19f, 1e20f, 1e25f, 1e30f})
    EXPECT_NEAR(mean_over_geometry(ao_at(radius), room.g), at_scale, 1e-3)
        << "R = " << radius << ", " << label;
}

}  // namespace aolab::testing
