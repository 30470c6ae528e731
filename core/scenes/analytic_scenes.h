// G-buffers of scenes with known answers, rendered exactly (double precision ray casting of
// clipped planes) for known-answer tests, the stability suite and benchmarks.
#pragma once

#include <functional>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <string>
#include <vector>

#include "core/base/camera.h"
#include "core/base/image.h"
#include "core/base/settings.h"
#include "core/base/triangle_mesh.h"

namespace aolab {

/// A convex piece of the plane dot(normal, X) = offset (world space), keeping the points
/// with dot(c.xyz, X) <= c.w for every clip c.
struct AnalyticFace {
  glm::dvec3 normal{0, 0, 1};
  double offset = 0;
  std::vector<glm::dvec4> clips;
  /// Closed-form Cycles AO (cosine-weighted visibility, hard cut-off R: docs/blender_facts.md,
  /// "The Cycles AO pass") at a world point of this face, or empty when none is known.
  std::function<double(const glm::dvec3& point, double radius)> cycles_ao;
};

struct AnalyticScene {
  std::vector<AnalyticFace> faces;
  glm::dvec3 eye{0, 0, 0}, target{0, 0, -1}, up{0, 1, 0};  ///< look-at camera, world space
  double fov_deg = 60;                                     ///< horizontal field of view
};

/// A rendered analytic scene: planar depth (background 1e10, as Cycles writes), view-space
/// unit normals facing the camera ((0,0,0) on background), the closed-form Cycles AO for
/// radius R where the scene has one (NaN elsewhere; 1 on background), the intrinsics
/// (square pixels, principal point at the centre) and the camera-to-world matrix.
struct AnalyticGBuffer {
  Image depth, normal, reference;
  CameraIntrinsics camera;
  glm::dmat4 camera_to_world{1.0};
};

/// Depth written where a ray hits nothing (Cycles' value).
constexpr float kAnalyticBackgroundDepth = 1e10f;

AnalyticGBuffer render_analytic_scene(const AnalyticScene& scene, int width, int height,
                                      double radius);

/// Names of the built-in scenes: plane, ceiling, wall, crease, step, blocks.
std::vector<std::string> analytic_scene_names();

/// One built-in scene. `params` (all optional; unknown names throw std::invalid_argument
/// listing the valid ones) set its geometry and field of view, and "radius" (default 1) the
/// R of the closed-form reference. See docs/analytic_scenes.md.
AnalyticGBuffer analytic_scene(const std::string& name, int width, int height,
                               const SettingValues& params = {});

/// The geometry of a built-in scene (the same names and params as analytic_scene).
AnalyticScene analytic_scene_geometry(const std::string& name, const SettingValues& params = {});

/// The faces of `scene` as triangles in world space, for a ray tracer: each face is the square
/// of half-side `extent` centred at the point of its plane nearest the camera, clipped by the
/// face's clips (Sutherland-Hodgman) and cut into a fan. An unbounded plane thus ends `extent`
/// from the camera: its closed form holds at points farther than R from that edge.
TriangleMesh analytic_scene_mesh(const AnalyticScene& scene, double extent);

/// Cycles' AO at distance `distance` from the crease of two perpendicular planes (a floor
/// beside a wall): 1 - (acos a - a·sqrt(1 - a²))/π for a = distance/R < 1, else 1.
double cycles_ao_beside_wall(double distance, double radius);
/// Cycles' AO on a plane under a parallel plane at height h: (h/R)² for R > h, else 1.
double cycles_ao_under_ceiling(double height, double radius);

}  // namespace aolab
