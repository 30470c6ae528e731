// The screen-space limit: the reference's own definition of AO evaluated on what a
// screen-space method can see. Not a published method but a bound: the best any method that
// reads only this G-buffer could do, which the study shows beside the contenders.
//
// The reference is Cycles' AO pass (docs/blender_facts.md, "The Cycles AO pass"):
//   A(P) = (1/π) ∫_Ω V_R(P, ω) (n·ω) dω,     V_R = 0 if a ray from P along ω hits within R,
// estimated with N cosine-weighted directions (pdf (n·ω)/π), stratified on the unit square
// and mapped to the disk by Shirley & Chiu, "A Low Distortion Map Between Disk and Square"
// (JGT 1997), then lifted to the hemisphere (Malley's method):
//   Â = 1 − Σ_k w_k (1 − V_R(P, ω_k)),      Σ w_k = 1,  w_k = the area of ray k's stratum.
// V_R is read from the depth buffer: each ray is marched in screen space over every pixel its
// projection crosses (Amanatides & Woo, "A Fast Voxel Traversal Algorithm for Ray Tracing",
// Eurographics 1987, in 2-D) and is blocked where it passes behind a crossed pixel's surface
// by less than `thickness` (docs/methods/screen_space_limit.md gives the details).
#pragma once

#include <vector>

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/settings.h"
#include "core/methods/registry.h"

namespace aolab {

/// Rays per pixel by default: 16 × 16 strata, a binomial standard error of at most
/// 0.5/√256 = 0.031 per pixel — a bound's noise must sit well below the errors it bounds.
constexpr int kScreenSpaceLimitDefaultRays = 256;

/// The largest thickness, and its default: 1e30 view-space units stands for "unbounded"
/// (everything behind a visible surface is solid, a height field). The settings tables keep
/// every value finite, and no depth buffer comes near 1e30.
constexpr float kScreenSpaceLimitUnbounded = 1e30f;

/// Float rounding must not create occlusion: a point counts as behind a pixel's surface only
/// if it lies behind that surface's plane by more than this share of its distance from the
/// camera (depths and normals are float32, unit roundoff 6e-8; 2^-17 ≈ 7.6e-6 leaves a
/// factor 128 for the rounding of plane offsets, normals and the march). Occluders nearer
/// than that to a surface are lost; the closed forms cannot see the difference.
constexpr double kScreenSpaceLimitPlaneTolerance = 1.0 / 131072.0;

/// Rays heading towards the camera are cut where their depth falls to this share of the
/// receiver's depth: the pinhole projection needs depth > 0, and an occluder nearer than
/// that to the camera is beyond any depth range a G-buffer holds (the stability suite mixes
/// depths 1e-3 and 1e5 in one frame, a ratio 1e-8).
constexpr double kScreenSpaceLimitNearCut = 1e-12;

struct ScreenSpaceLimitSettings {
  /// R: the AO distance in view-space units (the reference's). [1e-12, 1e30].
  float radius = 1.0f;
  /// N: cosine-weighted rays per pixel, stratified in ⌊√N⌋ columns. [1, 65536].
  int rays = kScreenSpaceLimitDefaultRays;
  /// T: how far behind a visible surface the scene is solid, a view-space depth. 0: nothing
  /// occludes; 1e30 (the default): unbounded, a height field. [0, 1e30].
  float thickness = kScreenSpaceLimitUnbounded;
  /// Seed of the per-pixel jitter within the strata. [0, 2^31 - 1].
  int seed = 0;
};

inline const SettingField<ScreenSpaceLimitSettings> kScreenSpaceLimitFields[] = {
    {"radius", &ScreenSpaceLimitSettings::radius, 1e-12, 1e30, "view-space units",
     "R, the AO distance: a hit within R occludes (same as the reference's AO distance)"},
    {"rays", &ScreenSpaceLimitSettings::rays, 1, 65536, "",
     "N, stratified cosine-weighted rays per pixel"},
    // The bound is the float default itself (1e30f = 1.0000000150e30), so that the default
    // passed back as a number is in range.
    {"thickness", &ScreenSpaceLimitSettings::thickness, 0, double(kScreenSpaceLimitUnbounded),
     "view-space units",
     "T, how far behind each visible surface the scene is solid (0: nothing occludes; 1e30: "
     "unbounded, a height field)"},
    {"seed", &ScreenSpaceLimitSettings::seed, 0, 2147483647, "",
     "seed of the per-pixel jitter within the strata"},
};

/// The screen-space limit of a G-buffer with normals. Returns a 1-channel image in [0, 1];
/// background = 1. Throws std::invalid_argument for invalid settings, a G-buffer without
/// normals or an invalid G-buffer; Cancelled if cancelled.
Image screen_space_limit(const GBuffer& g, const ScreenSpaceLimitSettings& settings,
                         const RunOptions& options = {});

/// The limit at several thicknesses in one pass (`settings.thickness` is not read): each ray
/// is marched once and its smallest gap behind a crossed surface answers for every thickness,
/// so the pass costs about one run at the thinnest of them. Image k is bit for bit
/// screen_space_limit() with thickness = thicknesses[k]. Each thickness is validated like
/// the setting; an empty list throws std::invalid_argument.
std::vector<Image> screen_space_limit_thicknesses(const GBuffer& g,
                                                  const ScreenSpaceLimitSettings& settings,
                                                  const std::vector<float>& thicknesses,
                                                  const RunOptions& options = {});

/// The registry entry (a bound: Method::bound).
Method screen_space_limit_method();

}  // namespace aolab
