// Pinhole camera intrinsics in the view-space convention of docs/conventions.md:
// x right, y up, the camera looks down -z; pixel (i, j) has its centre at (i + 0.5, j + 0.5),
// column i from the left, row j from the top; depth d = -z > 0 is planar depth.
#pragma once

#include <glm/vec3.hpp>

namespace aolab {

struct CameraIntrinsics {
  float fx = 0;  ///< focal length in pixels along x, > 0
  float fy = 0;  ///< focal length in pixels along y, > 0 (fx * ax / ay for non-square pixels)
  float cx = 0;  ///< principal point, pixels from the left edge
  float cy = 0;  ///< principal point, pixels from the top edge

  /// Throws std::invalid_argument naming fx, fy, cx or cy when it is not finite or a focal
  /// length is not positive.
  void validate() const;

  /// View-space position of the point at pixel coordinates (px, py) (a pixel centre is
  /// (i + 0.5, j + 0.5)) and planar depth d: X = (px - cx)/fx·d, Y = -(py - cy)/fy·d, Z = -d.
  glm::vec3 view_position(float px, float py, float depth) const {
    return {(px - cx) / fx * depth, -(py - cy) / fy * depth, -depth};
  }
  /// Inverse of view_position: returns (px, py, depth) of a view-space point with z < 0.
  glm::vec3 project(const glm::vec3& p) const {
    const float d = -p.z;
    return {cx + fx * p.x / d, cy - fy * p.y / d, d};
  }
};

}  // namespace aolab
