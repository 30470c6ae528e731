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

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/base/settings.h"
#include "core/methods/registry.h"
#include "core/raytracing/ray_scene.h"

namespace aolab {

/// Rays per pixel by default: the reference's own 1024 samples, so that `aolab rtao` at its
/// defaults is a second reference (binomial standard error at most 0.5/√1024 = 0.016 per
/// pixel, less with stratification).
constexpr int kRtaoDefaultRays = 1024;

/// The ray origin is lifted off the surface along the normal by
///   ε = kRtaoOffsetPixels · d / min(fx, fy) + kRtaoOffsetRounding · L,
/// d the depth, L the mesh's coordinate scale (RayScene::coordinate_scale: the largest
/// distance of a vertex from the world origin or the camera). Why:
/// - Cycles renders the G-buffer with a 0.01-pixel filter, so the depth it stores is that of
///   a camera ray up to 0.005 px from the pixel centre. Rebuilt on the centre's ray, the point
///   misses the surface along its normal by at most 0.005 · d/f (for a plane through P with
///   normal n the miss is 0.005 · d/f · |n_x|, whatever the grazing angle). 0.01 pixel
///   footprints is twice that bound.
/// - Float32 rounding: Blender's object-to-world transform, the world-space file, the move to
///   view space and the stored depth each move a triangle or a point by at most 2^-24 of a
///   coordinate, and every coordinate of a point on a triangle is at most L. 2^-21 is twice
///   their sum. A 1 km scene thus gets ε ≥ 0.5 mm everywhere, a 10 m room 5 µm.
/// Occluders closer than ε to the surface are lost (docs/methods/rtao.md gives ε per scene).
constexpr double kRtaoOffsetPixels = 0.01;
constexpr double kRtaoOffsetRounding = 1.0 / 2097152.0;

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

/// The ray-traced AO of every geometry pixel of `g` (with normals) against `scene` (the same
/// camera's view space). Returns a 1-channel image in [0, 1]; background = 1. Deterministic:
/// the same bits for any thread count. Throws std::invalid_argument for invalid settings, a
/// G-buffer without normals or an invalid G-buffer; Cancelled if cancelled.
Image rtao(const GBuffer& g, const RayScene& scene, const RtaoSettings& settings,
           const RunOptions& options = {});

/// The settings described for Python, the command line and docs (rtao is not in the method
/// registry: it needs the scene's triangles, not only a G-buffer).
std::vector<SettingDescription> rtao_setting_descriptions();

}  // namespace aolab
