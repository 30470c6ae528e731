// Pyramid HBAO: A. Astapov, V. Frolov, V. Galaktionov, "Pyramid HBAO — a Scalable
// Horizon-based Ambient Occlusion Method", GraphiCon 2021 (CEUR-WS Vol-3027, paper 5).
//
// A = 1 − (1/D) Σ_θ max_i W(r_i)·sin α_i          (eq. 8 per direction, averaged: §3.4 step 3)
// W(r) = max(0, 1 − r/R) (eq. 7; `attenuation = none`: W = 1 within R, the Cycles
// reference's hard cut-off); α_i is the elevation of sample S_i above P's tangent
// plane, sin α_i = n·(S_i − P)/|S_i − P| (the normal-oriented hemisphere of §2.2.1, eq. 2–5).
// Per direction, S reads on each level of a depth pyramid
// (core/methods/pyramid_hbao/depth_pyramid.h, §3.3), the step multiplied by K from one level to the
// next (§3.4); a blue-noise rotation, random directions and random start steps against patterns,
// then a Gaussian (§3.5). docs/methods/pyramid_hbao.md gives the details.
#pragma once

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/settings.h"
#include "core/methods/pyramid_hbao/depth_pyramid.h"
#include "core/methods/registry.h"

namespace aolab {

/// D = 8: the paper's experiments (§4: "The selected number of azimuth directions D=8").
constexpr int kPyramidHbaoDefaultDirections = 8;

/// S, reads per direction on each level. The paper's Table 1 lost its values in extraction.
/// Measured against the closed-form Cycles AO of the `wall` and `crease` scenes, S = 4 is
/// within 0.002 MAE of S = 8 at two thirds of the time, while S = 2 loses up to 0.05 (on
/// `ceiling`); at K = 3 it reaches 52 px in three levels (12 reads), past the median
/// projected radius (44 px) of the benchmark setting R = 0.25 (docs/methods/pyramid_hbao.md).
constexpr int kPyramidHbaoDefaultSamples = 4;

/// The random start-step multiplier m (§3.5) is uniform in [kPyramidHbaoStartMin,
/// kPyramidHbaoStartMax): its mean 1 keeps one read per texel of each level on average, and
/// its spread, a factor 3 = the default K, moves the radii where the march changes level
/// over a whole level, which breaks up the rings ("stepwise patterns") a fixed start leaves.
constexpr float kPyramidHbaoStartMin = 0.5f;
constexpr float kPyramidHbaoStartMax = 1.5f;

/// Float32 rounding must not create occlusion: a sample counts only if it lies nearer than
/// P's tangent plane, along the sample's own view ray, by more than
/// 2^-24 · depth · (kPyramidHbaoDepthUlps + kPyramidHbaoLevelUlps · l
///                  + kPyramidHbaoNormalUlps · g),
/// g = |r|/|n·r| summed over P's and the sample's rays (the rounding of the normal and of
/// the ray moves a tangent-plane depth by about 2^-24 · depth · g; large at grazing angles),
/// l the pyramid level (each level's mean adds at most half a unit of rounding, and its
/// centroid rounding moves the ray). Averaged planes lie on or behind themselves (Jensen,
/// depth_pyramid.h), so an unoccluded plane gives exactly 1; only occluders within a few
/// units of rounding of the tangent plane are lost.
constexpr float kPyramidHbaoDepthUlps = 8.0f;
constexpr float kPyramidHbaoLevelUlps = 2.0f;
constexpr float kPyramidHbaoNormalUlps = 4.0f;

/// W(r) of eq. 7, as HBAO's HbaoAttenuation.
enum class PyramidHbaoAttenuation : int {
  Linear = 0,  ///< W = max(0, 1 − r/R) (eq. 7, the paper's)
  None = 1,    ///< W = 1 within R: eq. 8 becomes max_i sin α_i, as in Cycles' AO pass
};

struct PyramidHbaoSettings {
  /// R: radius of influence in view-space units (the reference's AO distance). [1e-12, 1e30].
  float radius = 1.0f;
  /// D: azimuth directions per pixel (§3.4 step 1). [1, 64].
  int directions = kPyramidHbaoDefaultDirections;
  /// S: depth reads per direction on each pyramid level (§3.4 step 2a). [1, 64].
  int samples = kPyramidHbaoDefaultSamples;
  /// L: pyramid levels marched, level 0 (the depth buffer) included (§3.4 step 2).
  /// 0 = derived from R: level after level until the march passes the projected radius
  /// (the smallest L with m·S·(K^L − 1)/(K − 1) ≥ R·f/d), leaves the image or passes the
  /// 1×1 level. A positive L also stops at the projected radius; it caps the reach at
  /// m·S·(K^L − 1)/(K − 1) pixels. [0, 32].
  int levels = 0;
  /// K: reduction factor of the pyramid, and the factor of the step from one level to the
  /// next (§3.3: "K was chosen to be 3"). [2, 16].
  int reduction = kDepthPyramidDefaultReduction;
  /// PyramidHbaoAttenuation: W(r) in eq. 8. 0 linear (eq. 7, the paper's), 1 none (W = 1
  /// within R, the reference's hard cut-off: the highest sample above the tangent plane
  /// within R wins). [0, 1].
  int attenuation = int(PyramidHbaoAttenuation::Linear);
  /// Rotate the D directions per pixel by an angle from a 32×32 blue-noise texture (§3.5,
  /// first paragraph); off: no rotation.
  bool rotation = true;
  /// Random instead of uniform directions (§3.5, second paragraph): direction k lies at a
  /// random place in its own sector of 2π/D (stratified); off: at the sector's start.
  bool random_directions = true;
  /// Multiply each direction's start step by a random m in [0.5, 1.5) (§3.5, second
  /// paragraph); off: m = 1.
  bool random_start = true;
  /// Apply the paper's separable Gaussian (σ = 1.5 px, 5 taps: gaussian_blur with its
  /// defaults, §3.5) to the result. The paper's method includes it, so it is on by default;
  /// off gives the raw estimate (the paper's timings exclude the filter). Do not also pass
  /// blur=True to aolab.compute, which would filter a second time.
  bool gaussian_filter = true;
  /// Seed of the per-pixel randomness: a toroidal shift of the blue-noise texture and a
  /// global rotation, and the white noise of the directions and start steps. [0, 2^31 - 1].
  int seed = 0;
};

inline const SettingField<PyramidHbaoSettings> kPyramidHbaoFields[] = {
    {"radius", &PyramidHbaoSettings::radius, 1e-12, 1e30, "view-space units",
     "R, radius of influence (same as the reference's AO distance)"},
    {"directions", &PyramidHbaoSettings::directions, 1, 64, "", "D, azimuth directions per pixel"},
    {"samples", &PyramidHbaoSettings::samples, 1, 64, "",
     "S, depth reads per direction on each pyramid level"},
    {"levels", &PyramidHbaoSettings::levels, 0, 32, "",
     "L, pyramid levels marched including the depth buffer; 0 = as many as the radius needs"},
    {"reduction", &PyramidHbaoSettings::reduction, 2, 16, "",
     "K, pyramid reduction factor and step growth per level"},
    {"attenuation", &PyramidHbaoSettings::attenuation, 0, 1, "",
     "W(r) in eq. 8: linear, the paper's max(0, 1 - r/R) (eq. 7); none, W = 1 within R as in "
     "the reference",
     "linear|none"},
    {"rotation", &PyramidHbaoSettings::rotation, 0, 1, "",
     "rotate the directions per pixel by a 32x32 blue-noise angle"},
    {"random_directions", &PyramidHbaoSettings::random_directions, 0, 1, "",
     "place each direction randomly in its sector instead of uniformly"},
    {"random_start", &PyramidHbaoSettings::random_start, 0, 1, "",
     "multiply each direction's start step by a random factor in [0.5, 1.5)"},
    {"gaussian_filter", &PyramidHbaoSettings::gaussian_filter, 0, 1, "",
     "apply the paper's separable Gaussian (sigma 1.5 px, 5 taps) to the result"},
    {"seed", &PyramidHbaoSettings::seed, 0, 2147483647, "", "seed of the per-pixel randomness"},
};

/// Pyramid HBAO of a G-buffer with normals. Returns a 1-channel image in [0, 1];
/// background = 1. Throws std::invalid_argument for invalid settings, a G-buffer without
/// normals (estimate them with prepared_normals if needed) or an invalid G-buffer;
/// Cancelled if cancelled (the final Gaussian is neither counted nor cancellable).
Image pyramid_hbao(const GBuffer& g, const PyramidHbaoSettings& settings,
                   const RunOptions& options = {});

/// The registry entry.
Method pyramid_hbao_method();

/// One direction of a pixel (§3.4 step 1, §3.5).
struct PyramidHbaoDirection {
  float cos_theta;  ///< view-space azimuth θ, measured from +x towards +y (up)
  float sin_theta;
  float start;  ///< m, the start-step multiplier
};

/// The D directions of pixel (x, y): θ_k = 2π (k + b + δ_k) / D with b the blue-noise
/// rotation and δ_k ∈ [0, 1) the random place in the sector (each 0 when switched off),
/// and m_k. `out` holds settings.directions entries. Exposed for the tests.
void pyramid_hbao_directions(const PyramidHbaoSettings& settings, int x, int y,
                             PyramidHbaoDirection* out);

}  // namespace aolab
