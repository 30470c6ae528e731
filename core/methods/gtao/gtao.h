// Ground-truth-based ambient occlusion (GTAO): Jimenez, Wu, Pesce, Jarabo, "Practical
// Real-Time Strategies for Accurate Indirect Occlusion", Activision technical memo
// ATVI-TR-16-01 / SIGGRAPH 2016 course "Physically Based Shading in Theory and Practice".
//
// Cosine-weighted visibility A = (1/π) ∫_0^π ∫_{h1(φ)}^{h2(φ)} cos(θ − n)⁺ |sin θ| dθ dφ over
// slices φ around the per-pixel view vector v (§4, the slice formulation). Per slice: h1, h2
// the horizon angles from v on the two sides (max cosine of the samples within R), clamped to
// the hemisphere of the projected normal, h1 = n + max(h1 − n, −π/2), h2 = n + min(h2 − n, π/2);
// n the signed angle between the normal projected onto the slice plane and v; the inner
// integral a(h) = ¼(−cos(2h − n) + cos n + 2h sin n) per side (eq. 7), weighted by |proj n|
// (eq. 8). docs/methods/gtao.md gives the details and the normalisation.
#pragma once

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/settings.h"
#include "core/methods/registry.h"

namespace aolab {

/// Slices and steps per side of XeGTAO's "High" quality level, its default (XeGTAO's quality
/// levels: slices 1/2/3/9, steps 2/2/3/3 for low/medium/high/ultra).
constexpr int kGtaoDefaultSlices = 3;
constexpr int kGtaoDefaultSteps = 3;

/// The albedo the multi-bounce fit assumes: 0.8, the base colour of Blender's default
/// material, so a scene without materials gets the bounce its render would have.
constexpr float kGtaoDefaultAlbedo = 0.8f;

/// The memo's multi-bounce fit (cubic in AO, linear in albedo ρ): a = 2.0404ρ − 0.3324,
/// b = −4.7951ρ + 0.6417, c = 2.7552ρ + 0.6903; AO' = max(AO, ((a·AO + b)·AO + c)·AO).
constexpr float kGtaoBounceA[2] = {2.0404f, -0.3324f};
constexpr float kGtaoBounceB[2] = {-4.7951f, 0.6417f};
constexpr float kGtaoBounceC[2] = {2.7552f, 0.6903f};

/// How the slices' sum is turned into visibility.
enum class GtaoNormalization : int {
  /// Σ_k |proj n|·(a(h1) + a(h2)) / Σ_k |proj n|·(a(n − π/2) + a(n + π/2)): divided by what the
  /// same slices give with nothing above the tangent plane (ours). Exactly 1 on open planes
  /// for any slice count; the same limit as `slices` as the slices become many.
  Unoccluded = 0,
  /// (1/N) Σ_k |proj n|·(a(h1) + a(h2)): the slice average that estimates (1/π) ∫_0^π dφ, as
  /// the memo's Algorithm 1, XeGTAO and EEVEE do. Not 1 on open planes where n ≠ v (the
  /// unoccluded integrand |proj n|(cos n + n sin n) varies with φ), so the result is clamped.
  Slices = 1,
};

struct GtaoSettings {
  /// R: radius of influence in view-space units (the reference's AO distance). [1e-12, 1e30].
  float radius = 1.0f;
  /// Slices per pixel: screen-space directions spread over a half turn, φ_k = π(k + u)/N. [1, 64].
  int slices = kGtaoDefaultSlices;
  /// Samples per side of each slice, equally spaced over the projected radius. [1, 512].
  int steps = kGtaoDefaultSteps;
  /// Rotate the slices by a random fraction u of their spacing per pixel (the memo's spatial
  /// noise, which its denoiser averages); off: u = 0.
  bool random_rotation = true;
  /// Jitter the samples per pixel: sample i at (i − v)·step, v ∈ [0, 1); off: at i·step.
  bool jitter = true;
  /// Width of the linear fade of a sample's weight before R, as a fraction of R (XeGTAO's
  /// FalloffRange, whose tuned value is 0.615); 0 = the memo's hard cut at R, which is also
  /// Cycles' AO distance. [0, 1].
  float falloff = 0.0f;
  /// The memo's thickness heuristic (§4.3, "Height-field assumption considerations"): a sample
  /// whose horizon cosine falls below the current one pulls the horizon towards it by this
  /// blend factor, so thin occluders stop shadowing what lies behind them. 0 = off, the plain
  /// max of the horizon cosines. [0, 1].
  float thickness = 0.0f;
  /// GtaoNormalization: 0 unoccluded (ours, exact on planes), 1 slices (the memo's 1/N).
  int normalization = int(GtaoNormalization::Unoccluded);
  /// The memo's multi-bounce fit. Off by default: Cycles' AO pass has no bounces.
  bool multi_bounce = false;
  /// ρ of the multi-bounce fit (a scalar albedo for every pixel). [0, 1].
  float albedo = kGtaoDefaultAlbedo;
  /// Seed of the per-pixel random rotation and jitter. [0, 2^31 - 1].
  int seed = 0;
};

inline const SettingField<GtaoSettings> kGtaoFields[] = {
    {"radius", &GtaoSettings::radius, 1e-12, 1e30, "view-space units",
     "R, radius of influence (same as the reference's AO distance)"},
    {"slices", &GtaoSettings::slices, 1, 64, "",
     "slices per pixel (screen directions over a half turn)"},
    {"steps", &GtaoSettings::steps, 1, 512, "", "samples per side of each slice"},
    {"random_rotation", &GtaoSettings::random_rotation, 0, 1, "",
     "rotate the slices randomly per pixel"},
    {"jitter", &GtaoSettings::jitter, 0, 1, "", "jitter the sample offsets randomly per pixel"},
    {"falloff", &GtaoSettings::falloff, 0, 1, "fraction of R",
     "width of the linear fade of a sample's weight before R; 0 = hard cut at R"},
    {"thickness", &GtaoSettings::thickness, 0, 1, "",
     "thickness heuristic: blend of the horizon towards a sample below it; 0 = plain max"},
    {"normalization", &GtaoSettings::normalization, 0, 1, "",
     "divide by the unoccluded sum of the same slices (exact on planes) or by the slice count "
     "(the memo's)",
     "unoccluded|slices"},
    {"multi_bounce", &GtaoSettings::multi_bounce, 0, 1, "",
     "apply the memo's multi-bounce fit in albedo (Cycles' AO has no bounces)"},
    {"albedo", &GtaoSettings::albedo, 0, 1, "", "albedo of the multi-bounce fit"},
    {"seed", &GtaoSettings::seed, 0, 2147483647, "", "seed of the per-pixel randomness"},
};

/// The multi-bounce fit of the memo for visibility `ao` and albedo `albedo`.
float gtao_multi_bounce(float ao, float albedo);

/// The inner integral of one side (eq. 7): ¼(−cos(2h − n) + cos n + 2h sin n); the second
/// form takes cos n and sin n, which a slice computes once for both sides.
double gtao_arc(double h, double n, double cos_n, double sin_n);
double gtao_arc(double h, double n);

/// GTAO of a G-buffer with normals. Returns a 1-channel image in [0, 1]; background = 1.
/// Throws std::invalid_argument for invalid settings, a G-buffer without normals or an
/// invalid G-buffer; Cancelled if cancelled.
Image gtao(const GBuffer& g, const GtaoSettings& settings, const RunOptions& options = {});

/// The registry entry.
Method gtao_method();

}  // namespace aolab
