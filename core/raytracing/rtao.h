// rtao: Cycles' AO integral ray traced against the scene's triangles (Embree, ray_scene.h)
// from the points of a G-buffer. Not a screen-space method: a CPU peer of the screen-space
// methods, and an independent check of the Cycles references (docs/methods/rtao.md).
//
//   A(P) = (1/π) ∫_Ω V_R(P, ω) (n·ω) dω,     V_R = 0 if a ray from P along ω hits within R,
//
// estimated with N stratified cosine-weighted rays (core/sampling/cosine_hemisphere.h), the
// estimator the screen-space limit uses, but with V_R answered by the true geometry instead
// of the depth buffer. P is rebuilt from the pixel's depth and the intrinsics (the pixel
// centre's camera ray at that depth) and n is the G-buffer's prepared normal.
#pragma once

#include <cstddef>
#include <string>

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/base/run_options.h"
#include "core/base/settings.h"
#include "core/raytracing/ray_scene.h"

namespace aolab {

/// Rays per pixel by default: the reference's own 1024 samples, so that `aolab rtao` at its
/// defaults is a second reference (binomial standard error at most 0.5/√1024 = 0.016 per
/// pixel, less with stratification).
constexpr int kRtaoDefaultRays = 1024;

/// The ray origin is lifted off the surface along the normal by
///   ε = kRtaoOffsetPixels · d / min(fx, fy) + kRtaoOffsetRounding · L_p,
///   L_p = |P| + min(|c| + R + D, L),
/// d the pixel's depth, |P| the point's distance from the camera, |c| the camera's distance
/// from the world origin, R the AO distance, D the scene's longest triangle edge and L the
/// largest distance of a vertex from the world origin or from the camera
/// (RayScene::camera_distance, longest_edge, coordinate_scale). Why:
/// - Cycles renders the G-buffer with a 0.01-pixel filter, so the depth it stores is that of
///   a camera ray up to 0.005 px from the pixel centre. Rebuilt on the centre's ray, the point
///   misses the surface along its normal by at most 0.005 · d/f (for a plane through P with
///   normal n the miss is 0.005 · d/f · |n_x|, whatever the grazing angle). 0.01 pixel
///   footprints is twice that bound.
/// - Float32 rounding: Blender's object-to-world transform, the world-space file, the move to
///   view space and the stored depth each move a triangle or a point by at most 2^-24 of a
///   coordinate; 2^-21 is twice their sum. The coordinates that matter are P's and those of
///   the triangles a ray from P can reach within R, and a triangle is rounded through its
///   vertices, not at the point a ray meets it (a 2 km plane's corners round to 6·10⁻⁵ and
///   the plane near the camera moves by as much: a bound on that point alone failed the
///   open-plane test at 89° of tilt). A reachable triangle has a point within R of P (ε < R),
///   and no point of a triangle lies farther than its longest edge from a vertex, so its
///   vertices lie within R + D of P: at most |c| + |P| + R + D from the world origin and
///   |P| + R + D from the camera, and never beyond L. A triangle no ray from P reaches does
///   not count: a small one 10⁷ away used to lift every ray by 5 m, when the scale was L.
/// Occluders nearer than ε to the surface are lost, so ε is held against R, pixel by pixel
/// (docs/conventions.md, "Ranges"): rtao refuses a G-buffer on which ε ≥ R at some pixel, and
/// warns (the Python layer) where ε > kRtaoOffsetWarning · R.
constexpr double kRtaoOffsetPixels = 0.01;
constexpr double kRtaoOffsetRounding = 1.0 / 2097152.0;
/// ε above this share of R loses a measurable part of the occluders nearest the surface: at a
/// crease, about that share of the occlusion.
constexpr double kRtaoOffsetWarning = 0.01;

struct RtaoSettings {
  /// R: the AO distance in view-space units (the reference's): a hit within R occludes.
  /// [1e-12, 1e30].
  float radius = 1.0f;
  /// N: cosine-weighted rays per pixel, stratified in ⌊√N⌋ columns. [1, 65536].
  int rays = kRtaoDefaultRays;
  /// Seed of the per-pixel jitter within the strata. [0, 2^31 - 1].
  int seed = 0;
};

inline const SettingField<RtaoSettings> kRtaoFields[] = {
    {"radius", &RtaoSettings::radius, 1e-12, 1e30, "view-space units",
     "R, the AO distance: a hit within R occludes (same as the reference's AO distance)"},
    {"rays", &RtaoSettings::rays, 1, 65536, "", "N, stratified cosine-weighted rays per pixel"},
    {"seed", &RtaoSettings::seed, 0, 2147483647, "",
     "seed of the per-pixel jitter within the strata"},
};

/// The ray offset of one pixel and its parts (kRtaoOffsetPixels above).
struct RtaoOffset {
  int x = -1, y = -1;
  double depth = 0;
  double point_distance = 0;  ///< |P|, from the camera
  double footprint = 0;       ///< kRtaoOffsetPixels · d / min(fx, fy)
  double scale = 0;           ///< L_p = |P| + min(|c| + R + D, L)
  double epsilon = 0;         ///< footprint + kRtaoOffsetRounding · scale
};

/// How the ray offset compares with R over the pixels rays are traced from (the geometry
/// pixels; none when the scene has no triangle): rtao's range rule.
struct RtaoRange {
  double radius = 0;
  double camera_distance = 0, longest_edge = 0, coordinate_scale = 0;  ///< |c|, D, L
  std::size_t pixels = 0;   ///< pixels rays are traced from
  std::size_t warned = 0;   ///< of them, those with ε > kRtaoOffsetWarning · R
  std::size_t refused = 0;  ///< of them, those with ε ≥ R
  std::size_t beyond = 0;   ///< of them, those whose ray origin may reach kMaxRayCoordinate
  RtaoOffset largest;       ///< the largest ε / R (the first in row order among equals)
  RtaoOffset first_beyond;  ///< the first pixel beyond the range, in row order
  /// Why rtao refuses this G-buffer, as its std::invalid_argument says it; empty if it traces.
  std::string refusal() const;
  /// The warning for warned > 0 (empty otherwise, and when rtao refuses).
  std::string warning() const;
};

/// The range rule of rtao over `g` against `scene` at AO distance `radius`, computed as rtao
/// computes its offsets. Throws std::invalid_argument for an invalid G-buffer or radius.
RtaoRange rtao_range(const GBuffer& g, const RayScene& scene, float radius, int threads = 0);

/// The ray-traced AO of every geometry pixel of `g` (with normals) against `scene` (the same
/// camera's view space). Returns a 1-channel image in [0, 1]; background = 1. Deterministic:
/// the same bits for any thread count. Throws std::invalid_argument for invalid settings, a
/// G-buffer without normals, an invalid G-buffer, or one rtao_range refuses (its refusal());
/// Cancelled if cancelled. `range`, if given, receives rtao_range's answer.
Image rtao(const GBuffer& g, const RayScene& scene, const RtaoSettings& settings,
           const RunOptions& options = {}, RtaoRange* range = nullptr);

/// The settings described for Python, the command line and docs (rtao is not in the method
/// registry: it needs the scene's triangles, not only a G-buffer).
std::vector<SettingDescription> rtao_setting_descriptions();

}  // namespace aolab
