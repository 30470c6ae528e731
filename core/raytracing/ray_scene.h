// Triangles in view space, ready for ray queries: the scene geometry the bridge exports
// (`mesh` pass: world-space triangles, docs/file_formats.md) moved into the G-buffer's view
// space and put in an Intel Embree BVH (Debian libembree-dev, Embree 3 or 4). The AO
// estimator on top of it is rtao.h.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <glm/mat4x4.hpp>
#include <memory>
#include <vector>

#include "core/base/triangle_mesh.h"

namespace aolab {

/// A row-major 4×4 matrix (the sidecar's camera_to_world).
using Matrix4 = std::array<double, 16>;

/// A glm matrix (column-major: m[column][row]; the analytic scenes' camera_to_world) as a
/// Matrix4.
inline Matrix4 row_major(const glm::dmat4& m) {
  Matrix4 out;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[std::size_t(4 * r + c)] = m[c][r];
  return out;
}

/// The largest magnitude of a coordinate the ray tracer represents: Embree's FLT_LARGE
/// (1.844e18, about √FLT_MAX / 10, so that the product of two coordinates stays finite).
/// Embree silently drops a triangle with a vertex coordinate at or beyond it, and a ray whose
/// origin has one fails Embree's assertion, which ends the process: RayScene refuses such
/// vertices and rtao such ray origins (docs/conventions.md, "Ranges").
constexpr float kMaxRayCoordinate = 1.844e18f;

/// Throws std::invalid_argument naming camera_to_world unless `m` is finite, its upper 3×3 a
/// rotation (columns orthonormal to within a tolerance that admits the rounding of the
/// sidecar's scale-removed matrix, nothing more) and its last row (0, 0, 0, 1): the camera
/// matrices AO Lab can move triangles and normals with. A camera under a parent scaled
/// unevenly and rotated is sheared, and fails. The one rule of RayScene and of the Blender
/// bridge, which checks a camera with it before rendering.
void check_camera_to_world(const Matrix4& m);

/// The triangles of a mesh in view space, in an Embree BVH. Immutable once built: queries
/// from any number of threads at once.
class RayScene {
 public:
  /// Moves `world_mesh` into view space with the inverse of `camera_to_world` (a rigid
  /// transform: rotation and translation, no scale, as the sidecar stores it; in double, then
  /// rounded to float once) and builds the BVH on `threads` threads (0 = all cores).
  /// Throws std::invalid_argument naming the parameter for a malformed mesh (a vertex count
  /// not a multiple of 3, an index out of range, a non-finite vertex, a vertex whose view-space
  /// coordinates reach kMaxRayCoordinate), a camera_to_world that is not finite or not rigid,
  /// or a negative thread count; std::runtime_error if Embree fails (out of memory).
  RayScene(const TriangleMesh& world_mesh, const Matrix4& camera_to_world, int threads = 0);
  ~RayScene();
  RayScene(RayScene&&) noexcept;
  RayScene& operator=(RayScene&&) noexcept;
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  /// Whether the segment from `origin` along the unit `direction` over [0, t_far] hits a
  /// triangle (either side: back faces occlude, as in Cycles' AO pass). View space.
  bool occluded(const float origin[3], const float direction[3], float t_far) const;

  /// Occlusion of `count` segments from one origin, direction k being (dx[k], dy[k], dz[k]):
  /// blocked[k] tells whether it hits within t_far, exactly as occluded() would. Uses Embree's
  /// packet traversal where it pays.
  void occluded_from(const float origin[3], const float* dx, const float* dy, const float* dz,
                     int count, float t_far, bool* blocked) const;

  std::size_t triangle_count() const { return triangles_; }
  /// Wall-clock seconds the BVH build took (Embree's rtcCommitScene), for the study's
  /// "BVH build timed apart".
  double build_seconds() const { return build_seconds_; }
  /// The scales of the float32 rounding of the triangles (rtao.h, kRtaoOffsetRounding):
  /// L, the largest distance of a vertex from the world origin or from the camera; |c|, the
  /// camera's distance from the world origin; D, the longest edge of a triangle (0 without
  /// triangles).
  double coordinate_scale() const { return coordinate_scale_; }
  double camera_distance() const { return camera_distance_; }
  double longest_edge() const { return longest_edge_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::size_t triangles_ = 0;
  double build_seconds_ = 0;
  double coordinate_scale_ = 0, camera_distance_ = 0, longest_edge_ = 0;
};

}  // namespace aolab
