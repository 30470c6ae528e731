// The G-buffer every method reads, the background rule and the validity mask.
#pragma once

#include <cmath>
#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "core/base/camera.h"
#include "core/base/image.h"

namespace aolab {

/// Depth at or above this is background. Cycles writes 1e10 where no geometry is hit;
/// 1e9 leaves every real depth (the stability suite goes to 1e5) on the geometry side.
/// EEVEE writes 65504 (half-float max): pass background_depth = 65504 for its buffers.
constexpr float kDefaultBackgroundDepth = 1e9f;

/// The background rule of docs/conventions.md: a pixel holds geometry iff its depth is
/// finite, > 0 and < background_depth. Background pixels get AO 1, never occlude anything
/// and are left out of every metric.
inline bool is_geometry(float depth, float background_depth) {
  return std::isfinite(depth) && depth > 0.0f && depth < background_depth;
}

/// Non-owning G-buffer: planar depth (1 channel), optional view-space normals (3 channels),
/// optional colour (3 or 4 channels; Cycles' DiffCol, the diffuse albedo) and optional
/// emission (3 or 4 channels; Cycles' Emit, the emitted radiance), all of one size, plus the
/// camera.
struct GBuffer {
  ConstImageView depth;
  ConstImageView normal;    ///< empty if absent
  ConstImageView color;     ///< empty if absent
  ConstImageView emission;  ///< empty if absent
  CameraIntrinsics camera;
  float background_depth = kDefaultBackgroundDepth;  ///< > 0; see kDefaultBackgroundDepth

  int width() const { return depth.width; }
  int height() const { return depth.height; }
  bool has_normal() const { return !normal.empty(); }
  bool has_color() const { return !color.empty(); }
  bool has_emission() const { return !emission.empty(); }
  bool valid(int x, int y) const { return is_geometry(depth(x, y), background_depth); }

  /// Throws std::invalid_argument naming the parameter: empty depth, wrong channel counts,
  /// size mismatches, invalid intrinsics or background_depth.
  void validate() const;
};

/// Throws std::invalid_argument naming "normal" unless `g` has normals: `method` reads them.
/// The one check behind the registry's compute() and each such method's own entry point.
void require_normal(const GBuffer& g, const std::string& method);

/// Throws std::invalid_argument naming "color" unless `g` has colour: `method` reads it,
/// always or, when `setting` is given, because that setting is on.
void require_color(const GBuffer& g, const std::string& method, const std::string& setting = "");

/// 1 where the pixel holds geometry, 0 for background (float so it can be a numpy mask).
Image validity_mask(const GBuffer& g);

/// The depth buffer as W·H floats, row-major, with every background pixel (is_geometry
/// false) replaced by NaN: the working copy the methods march over, where any comparison
/// with a background depth fails and so background never occludes. A working array: its memory
/// comes from the working-memory cache.
Buffer<float> depth_with_background_as_nan(const GBuffer& g, int threads = 0);

/// Per-pixel view-space positions (3 channels); background pixels get NaN.
Image view_positions(const GBuffer& g, int threads = 0);

/// Minimum |n| accepted as a normal; shorter (including zero) normals are replaced.
constexpr float kMinNormalLength = 1e-3f;

/// The normals methods actually use (3 channels), made well-defined at the boundary:
/// - non-unit normals (Blender's averaged normals are ~0.97 at edges) are renormalised;
/// - normals facing away from the camera (n·(-P) < 0) are flipped, as Cycles' Normal pass is;
/// - zero, too short (< kMinNormalLength) or non-finite normals, and all normals when the
///   G-buffer has none, are estimated from depth (normal_from_depth);
/// - background pixels get (0, 0, 0).
Image prepared_normals(const GBuffer& g, int threads = 0);

/// The prepared normal of pixel (x, y), as prepared_normals gives it: the rule above, pixel by
/// pixel (the reference for prepared_normals_row, and its path for the exceptions).
glm::vec3 prepared_normal(const GBuffer& g, int x, int y);

/// Row y of prepared_normals into out (3 floats per pixel), bit for bit prepared_normal:
/// gbuffer_simd.cpp does the usual pixel (geometry with a usable normal) in SIMD, in the
/// scalar code's order of operations and without fused multiply-adds, and calls
/// prepared_normal for the rest.
void prepared_normals_row(const GBuffer& g, int y, float* out);

/// Normal of the surface at (x, y) estimated from depth: the cross product of the smaller of
/// the left/right and of the up/down position differences (so a depth edge on one side is
/// ignored), facing the camera. Falls back to the direction towards the camera when no valid
/// neighbour exists (1x1 images, isolated pixels).
glm::vec3 normal_from_depth(const GBuffer& g, int x, int y);

}  // namespace aolab
