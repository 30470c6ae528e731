// Horizon-based ambient occlusion: Bavoil, Sainz, Dimitrov, "Image-Space Horizon-Based
// Ambient Occlusion", SIGGRAPH 2008 talk.
//
// A = 1 - (1/N_d) Σ_θ (sin h(θ) - sin t(θ)) W(θ)            (eq. 3, Monte Carlo over θ, §3)
// t(θ): tangent angle from the normal; h(θ) = max(t, α(S_i)) over N_s texel-centre samples
// within the eye-space radius R; α(S) = atan(D.z/|D.xy|), D = S - P; W = max(0, 1 - r/R)
// with r the distance to the horizon sample. Two settings offer the Cycles reference's
// definition instead of the paper's: `attenuation = none` (W = 1 within R) and
// `integral = cosine` (the band between t and h weighted by n·ω, the cosine-weighted AO).
// docs/methods/hbao.md gives the details.
#pragma once

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>
#include <vector>

#include "core/base/depth_mip.h"
#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/settings.h"
#include "core/horizon/directions.h"
#include "core/horizon/frame.h"
#include "core/horizon/receiver.h"
#include "core/methods/registry.h"

namespace aolab {

/// N_d and N_s of the paper's Figure 1 (8 directions, 8 steps).
constexpr int kHbaoDefaultDirections = 8;
constexpr int kHbaoDefaultSteps = 8;

/// Float32 rounding must not create occlusion: with per-sample tangents the tangent-plane test
/// of receiver.h decides (kTangentDepthUlps, kTangentNormalUlps). With the paper's
/// per-direction tangent the gain sin α - sin t must exceed kHbaoNormalTolerance +
/// kTangentDepthUlps · 2^-24 · max(d_P, d_S)/|D|. Either way an unoccluded plane gives exactly
/// 1; only occluders within a few ulps of depth of the tangent plane are lost.
constexpr float kHbaoNormalTolerance = 1e-6f;

/// The horizon point's distance r sets W (eq. 3), so the choice among samples of nearly
/// equal elevation must not hinge on rounding: a farther sample becomes the horizon only if
/// its sin α - sin t exceeds the current one by more than this (ties go to the nearer
/// sample, the first one met). 1e-5 in sine is far below any visible difference.
constexpr float kHbaoHorizonTie = 1e-5f;

/// W(r) of eq. 3: the paper's linear falloff, or none (the reference's hard cut-off at R).
enum class HbaoAttenuation : int {
  Linear = 0,  ///< W = max(0, 1 − r/R) (eq. 3)
  None = 1,    ///< W = 1: every horizon within R counts fully, as in Cycles' AO pass
};

/// How the band of elevations between t(θ) and h(θ) is weighted.
enum class HbaoIntegral : int {
  /// Eq. 1–3: uniform over the hemisphere (1/2π ∫ dω), per direction sin h − sin t.
  Uniform = 0,
  /// The reference's cosine-weighted AO (1/π ∫ (n·ω) dω): per direction
  /// a[(h − t) + sin h cos h − sin t cos t] + n_z (sin²h − sin²t), a = n.xy·û
  /// (hbao_cosine_band; the derivation is in docs/methods/hbao.md).
  Cosine = 1,
};

/// Twice the cosine-weighted solid angle, over 2π of azimuth, of the elevations from t to α in
/// the view-space azimuth û: 2 ∫_t^α (n·ω) cos φ dφ with ω = (cos φ û, sin φ) and
/// n·ω = a cos φ + n_z sin φ, a = n.xy·û. Averaged over N_d directions it is the
/// occlusion of the cosine-weighted AO, (1/π) ∫ (n·ω) dω over the occluded directions.
/// α − t is taken from the sines and cosines with atan2, which keeps it accurate near 0.
inline float hbao_cosine_band(float a, float nz, float sin_alpha, float cos_alpha, float sin_t,
                              float cos_t) {
  const float diff =
      std::atan2(sin_alpha * cos_t - cos_alpha * sin_t, cos_alpha * cos_t + sin_alpha * sin_t);
  return a * (diff + sin_alpha * cos_alpha - sin_t * cos_t) +
         nz * (sin_alpha * sin_alpha - sin_t * sin_t);
}

struct HbaoSettings {
  /// R: radius of influence in view-space units (the reference's AO distance). [1e-12, 1e30].
  float radius = 1.0f;
  /// N_d: directions around the view axis, uniformly spaced (§3). [1, 64].
  int directions = kHbaoDefaultDirections;
  /// N_s: equal steps the projected radius is split into (§3). [1, 512].
  int steps = kHbaoDefaultSteps;
  /// Rotate the N_d directions by a random angle per pixel ("trade banding for noise", §3).
  bool random_rotation = true;
  /// Jitter the steps per pixel: sample i at (i - u)·step, u ∈ [0, 1) per pixel (§3);
  /// off: at i·step.
  bool jitter = true;
  /// The paper finds t(θ) by intersecting a view ray with the tangent plane (§3).
  /// true: that construction on each sample's own view ray (through its snapped texel), so
  /// the sample is compared with the tangent plane where it actually is and a plane is
  /// exactly unoccluded. false: one t(θ) per direction, from the ray one pixel along θ;
  /// snapping moves samples off θ, so a tilted plane then occludes itself slightly.
  bool per_sample_tangent = true;
  /// HbaoIntegral: how the elevations between t and h are weighted. 0 uniform (eq. 1–3, the
  /// paper's: sin h − sin t), 1 cosine (the reference's cosine-weighted AO, a term of n·ω;
  /// hbao_cosine_band). The tangent mode still decides which samples count. [0, 1].
  int integral = int(HbaoIntegral::Uniform);
  /// HbaoAttenuation: W of eq. 3. 0 linear (the paper's W = 1 − r/R), 1 none (W = 1 within R,
  /// the reference's hard cut-off; incremental_attenuation then changes nothing). [0, 1].
  int attenuation = int(HbaoAttenuation::Linear);
  /// Where the linear W is evaluated. false (eq. 3, the paper's estimator): W = 1 - r/R with
  /// r the distance of the horizon sample, so a horizon that keeps rising towards R (a wall, a
  /// crease) is weighted by a W near 0. true (eq. 2 discretised, W(ω) inside the elevation
  /// integral): each rise of the direction's term (sin h, or the cosine band) along the march
  /// is weighted by W of the sample that caused it — the form of NVIDIA's HBAO
  /// implementations, with stronger creases.
  bool incremental_attenuation = false;
  /// Seed of the per-pixel random rotation and jitter. [0, 2^31 - 1].
  int seed = 0;
  /// q, in pixels: far samples read the depth MIP chain (depth_mip.h). A sample r ≥ 2q pixels
  /// from P snaps to the pixel of its 2^l block, l = min(floor(log2(r/q)), 5), and reads that
  /// pixel's exact depth from level l, whose texels lie 4^l times closer in memory: a large
  /// radius's samples then stay in the cache. The sample moves by at most 2^(l-1) ≤ r/(2q)
  /// pixels. 0: every sample reads the full-resolution depth, as in the paper. [0, 4096].
  float mip_distance = 0.0f;
};

inline const SettingField<HbaoSettings> kHbaoFields[] = {
    {"radius", &HbaoSettings::radius, 1e-12, 1e30, "view-space units",
     "R, radius of influence (same as the reference's AO distance)"},
    {"directions", &HbaoSettings::directions, 1, 64, "", "N_d, directions per pixel"},
    {"steps", &HbaoSettings::steps, 1, 512, "", "N_s, steps per direction"},
    {"random_rotation", &HbaoSettings::random_rotation, 0, 1, "",
     "rotate the directions randomly per pixel"},
    {"jitter", &HbaoSettings::jitter, 0, 1, "", "jitter the step offsets randomly per pixel"},
    {"per_sample_tangent", &HbaoSettings::per_sample_tangent, 0, 1, "",
     "intersect each sample's own view ray with the tangent plane (exact on planes); off: "
     "one tangent per direction, as the paper words it"},
    {"integral", &HbaoSettings::integral, 0, 1, "",
     "weight of the elevations between tangent and horizon: uniform, the paper's sin h - sin t "
     "(eq. 3); cosine, n.w as in the reference's cosine-weighted AO",
     "uniform|cosine"},
    {"attenuation", &HbaoSettings::attenuation, 0, 1, "",
     "W(r): linear, the paper's max(0, 1 - r/R) (eq. 3); none, W = 1 within R as in the "
     "reference",
     "linear|none"},
    {"incremental_attenuation", &HbaoSettings::incremental_attenuation, 0, 1, "",
     "weight each rise of the horizon by W of the sample that raised it (eq. 2) instead of "
     "W of the final horizon (eq. 3); linear attenuation only"},
    {"seed", &HbaoSettings::seed, 0, 2147483647, "", "seed of the per-pixel randomness"},
    {"mip_distance", &HbaoSettings::mip_distance, 0, 4096, "px",
     "q: a sample r >= 2q px away reads the depth MIP level floor(log2(r/q)) (at most 5), "
     "snapped to a pixel of that level, which keeps large radii in the cache; 0 = full "
     "resolution everywhere, as in the paper"},
};

/// HBAO of a G-buffer with normals. Returns a 1-channel image in [0, 1]; background = 1.
/// Throws std::invalid_argument for invalid settings, a G-buffer without normals (estimate
/// them with prepared_normals if needed) or an invalid G-buffer; Cancelled if cancelled.
Image hbao(const GBuffer& g, const HbaoSettings& settings, const RunOptions& options = {});

/// The registry entry.
Method hbao_method();

// ---- The per-pixel sampling pattern, shared with the textbook version (tests/textbook)
// so both sample the same texels; it re-derives everything else in double precision. ----

struct HbaoPixelPattern {
  float rotation;  ///< fraction of one direction spacing, [0, 1)
  float jitter;    ///< step offset u, [0, 1)
};

HbaoPixelPattern hbao_pixel_pattern(const HbaoSettings& s, int x, int y);

}  // namespace aolab
