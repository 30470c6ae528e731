// Scalable ambient obscurance (SAO): McGuire, Mara, Luebke, "Scalable Ambient Obscurance",
// HPG 2012. Alchemy AO's estimator (obscurance_estimator.h) made cheap at large radii:
//  (a) a camera-space-z pyramid by rotated-grid subsampling (§2.2):
//      z_{m+1}(x, y) = z_m(2x + ((y & 1) ⊕ 1), 2y + ((x & 1) ⊕ 1));
//  (b) s taps on a spiral (§2.3): α_i = (i + ½)/s, screen radius h_i = r'·α_i, angle
//      θ_i = 2π·α_i·τ + φ, r' the projected radius, φ a per-pixel rotation, τ from the
//      paper's low-discrepancy table (kSpiralTurns);
//  (c) tap i reads level m_i = clamp(⌊log2 h_i⌋ − q', 0, L_max) (§2.3), q' = log2 of the
//      tap distance at which the switch to coarser levels starts;
//  (d) the estimator A = max(0, 1 − (c·σ/s) Σ w(v_i) max(0, v_i·n̂ − β)/(v_i·v_i + ε))^k;
//  (e) a separable depth-aware Gaussian (§2.4): taps `filter_stride` pixels apart, weights
//      falling linearly to 0 with the depth difference;
//  (f) normals from the G-buffer or, as the paper does, from the depth derivatives of a 2×2
//      pixel quad.
// docs/methods/sao.md gives the details and the choices where the paper is silent.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/settings.h"
#include "core/horizon/obscurance_estimator.h"
#include "core/methods/registry.h"

namespace aolab {

/// s of the reference implementation's shader, for which its comment says τ was tuned (9).
constexpr int kSaoDefaultSamples = 9;
/// q' = 3 and L_max = 5: the reference implementation's LOG_MAX_OFFSET and MAX_MIP_LEVEL
/// (its note: q' < 3 puts too many taps on the same texel, q' > 5 wastes the levels).
constexpr int kSaoDefaultLogMaxOffset = 3;
constexpr int kSaoDefaultMaxMipLevel = 5;
/// β in units of r: the reference implementation's constant bias, 0.023 scene units at its
/// default radius 0.75 (AmbientOcclusionSettings), ≈ 0.03·r.
constexpr float kSaoDefaultBias = 0.03f;
/// ε in units of r²: the reference implementation's 0.01 ("large epsilon to avoid
/// overdarkening within cracks"), at r = 1.
constexpr float kSaoDefaultEpsilon = 0.01f;
/// The reconstruction filter of the reference implementation: 4 taps per side, 2 pixels
/// apart (the AO pass already mixes neighbours), weights of a Gaussian of σ = 3 taps (the
/// ratios of its weight table), edge sharpness 1.
constexpr int kSaoDefaultFilterRadius = 4;
constexpr int kSaoDefaultFilterStride = 2;
constexpr float kSaoDefaultFilterSigma = 3.0f;
/// The depth difference, in units of r, at which a filter tap's weight reaches 0 at edge
/// sharpness 1. The reference code's key is z/far and a tap's weight
/// max(0, 1 − 2000·sharpness·|Δkey|), 0 at |Δz| = far/2000 (0.15 with a 300 far plane);
/// AO Lab has no far plane, so the difference is measured against r: 0.2·r, 0.15 at the
/// reference's radius 0.75.
constexpr float kSaoFilterEdgeDepth = 0.2f;

/// Where a tap read from a coarse level is placed in view space.
enum class SaoTapPosition : int {
  /// At the pixel its depth was subsampled from (ours): the point lies on the surface, so a
  /// plane stays exactly unoccluded at every level.
  Source = 0,
  /// At the tap's own pixel, as the paper and its reference code do: coarse depths are moved
  /// by up to 2^m pixels, which darkens tilted planes slightly.
  Tap = 1,
};

/// The phase of the rotated grid.
enum class SaoGrid : int {
  Paper = 0,      ///< (2x + ((y & 1) ⊕ 1), 2y + ((x & 1) ⊕ 1)), the paper's §2.2 form
  Reference = 1,  ///< (2x + (y & 1), 2y + (x & 1)), the reference code's minify shader
};

/// The normals the estimator uses.
enum class SaoNormals : int {
  GBuffer = 0,  ///< the G-buffer's (prepared_normals)
  Depth = 1,    ///< the paper's: cross product of the 2×2 quad's position differences
};

struct SaoSettings {
  /// r: radius of influence in view-space units (the reference's AO distance). [1e-12, 1e30].
  float radius = 1.0f;
  /// s: taps per pixel on the spiral. [1, 98].
  int samples = kSaoDefaultSamples;
  /// τ: turns of the spiral; 0 = the paper's low-discrepancy table for s. [0, 98].
  int turns = 0;
  /// σ: intensity, in units of r. [0, 100].
  float intensity = 1.0f;
  /// k: contrast, the exponent of the result. [0.1, 10].
  float contrast = 1.0f;
  /// β: bias distance in units of r; a tap counts only where v·n exceeds it. [0, 1].
  float bias = kSaoDefaultBias;
  /// ε: added to v·v, in units of r². [0, 1].
  float epsilon = kSaoDefaultEpsilon;
  /// ObscuranceFalloff: 0 alchemy (taps beyond r dropped, the paper's estimator), 1 smooth
  /// ((1 − v·v/r²)³, the reference code's recommended one). [0, 1].
  int falloff = int(ObscuranceFalloff::Alchemy);
  /// q': log2 of the tap distance (pixels) at which taps move to coarser levels. [0, 16].
  int log_max_offset = kSaoDefaultLogMaxOffset;
  /// L_max: coarsest level of the z pyramid; 0 = full resolution only. [0, 16].
  int max_mip_level = kSaoDefaultMaxMipLevel;
  /// SaoGrid: phase of the rotated-grid subsampling: 0 paper, 1 reference code. [0, 1].
  int grid = int(SaoGrid::Paper);
  /// SaoTapPosition: 0 source (ours, exact on planes), 1 tap (the paper's). [0, 1].
  int tap_position = int(SaoTapPosition::Source);
  /// SaoNormals: 0 the G-buffer's, 1 from depth (the paper's quad derivatives). [0, 1].
  int normals = int(SaoNormals::GBuffer);
  /// Rotate the spiral by a random angle per pixel (the paper's per-pixel hash).
  bool random_rotation = true;
  /// The bilateral reconstruction (§2.4); off: the raw estimate.
  bool filter = true;
  /// Filter taps per side of the centre. [1, 32].
  int filter_radius = kSaoDefaultFilterRadius;
  /// Pixels between filter taps. [1, 16].
  int filter_stride = kSaoDefaultFilterStride;
  /// σ of the filter's Gaussian, in taps. [0.1, 100].
  float filter_sigma = kSaoDefaultFilterSigma;
  /// Edge sharpness: a tap's weight falls linearly to 0 at a depth difference of
  /// 0.2·r/sharpness; 0 = a plain Gaussian. [0, 1000].
  float edge_sharpness = 1.0f;
  /// Seed of the per-pixel rotation. [0, 2^31 - 1].
  int seed = 0;
};

inline const SettingField<SaoSettings> kSaoFields[] = {
    {"radius", &SaoSettings::radius, 1e-12, 1e30, "view-space units",
     "r, radius of influence (same as the reference's AO distance)"},
    {"samples", &SaoSettings::samples, 1, kSpiralMaxSamples, "", "s, taps per pixel"},
    {"turns", &SaoSettings::turns, 0, kSpiralMaxSamples, "",
     "tau, turns of the tap spiral; 0 = the paper's low-discrepancy table"},
    {"intensity", &SaoSettings::intensity, 0, 100, "units of r", "sigma, intensity"},
    {"contrast", &SaoSettings::contrast, 0.1, 10, "", "k, contrast (exponent of the result)"},
    {"bias", &SaoSettings::bias, 0, 1, "units of r", "beta: a tap counts where v.n exceeds it"},
    {"epsilon", &SaoSettings::epsilon, 0, 1, "units of r^2",
     "epsilon added to v.v (keeps close taps finite)"},
    {"falloff", &SaoSettings::falloff, 0, 1, "",
     "alchemy: taps beyond r dropped (the paper's); smooth: (1 - v.v/r^2)^3 (the reference "
     "code's)",
     "alchemy|smooth"},
    {"log_max_offset", &SaoSettings::log_max_offset, 0, 16, "",
     "q', log2 of the tap distance in pixels where coarser levels start"},
    {"max_mip_level", &SaoSettings::max_mip_level, 0, 16, "",
     "L_max, coarsest level of the z pyramid; 0 = full resolution only"},
    {"grid", &SaoSettings::grid, 0, 1, "",
     "phase of the rotated-grid subsampling: the paper's or the reference code's",
     "paper|reference"},
    {"tap_position", &SaoSettings::tap_position, 0, 1, "",
     "place a coarse tap at the pixel its depth came from (exact on planes) or at the tap's "
     "pixel (the paper's)",
     "source|tap"},
    {"normals", &SaoSettings::normals, 0, 1, "",
     "the G-buffer's normals or the paper's, from the depth of each 2x2 pixel quad",
     "gbuffer|depth"},
    {"random_rotation", &SaoSettings::random_rotation, 0, 1, "",
     "rotate the tap spiral randomly per pixel"},
    {"filter", &SaoSettings::filter, 0, 1, "", "the separable depth-aware Gaussian reconstruction"},
    {"filter_radius", &SaoSettings::filter_radius, 1, 32, "", "filter taps per side"},
    {"filter_stride", &SaoSettings::filter_stride, 1, 16, "pixels", "pixels between filter taps"},
    {"filter_sigma", &SaoSettings::filter_sigma, 0.1, 100, "taps",
     "sigma of the filter's Gaussian"},
    {"edge_sharpness", &SaoSettings::edge_sharpness, 0, 1000, "",
     "a filter tap's weight reaches 0 at a depth difference of 0.2 r / sharpness; 0 = plain "
     "Gaussian"},
    {"seed", &SaoSettings::seed, 0, 2147483647, "", "seed of the per-pixel randomness"},
};

/// One level of the z pyramid: per texel the depth (NaN = background) and the full-resolution
/// pixel it was subsampled from.
struct SaoZLevel {
  int width = 0, height = 0;
  Buffer<float> depth;          ///< a working array, as `source`
  Buffer<std::int32_t> source;  ///< y·W + x of the full-resolution pixel
};

/// The pyramid of levels 0..max_level (level 0 = `depth`, W × H, NaN = background); level
/// m + 1 is ⌈w_m/2⌉ × ⌈h_m/2⌉, its texel (x, y) a copy of level m's texel of the rotated grid
/// (coordinates clamped to level m). Threads as in RunOptions.
std::vector<SaoZLevel> sao_z_pyramid(std::span<const float> depth, int width, int height,
                                     int max_level, SaoGrid grid, int threads = 0);

/// The normals of the 2×2 pixel quads (SaoNormals::Depth): for pixel (x, y), the cross
/// product of the position differences across its quad's row and column (x ^ 1, y ^ 1 when
/// inside the image, else the other neighbour), facing the camera; `fallback` (3 channels)
/// where a needed neighbour is background.
Image sao_quad_normals(const GBuffer& g, std::span<const float> depth, ConstImageView fallback,
                       int threads = 0);

/// SAO of a G-buffer with normals. Returns a 1-channel image in [0, 1]; background = 1.
/// Throws std::invalid_argument for invalid settings, a G-buffer without normals or an
/// invalid G-buffer; Cancelled if cancelled.
Image sao(const GBuffer& g, const SaoSettings& settings, const RunOptions& options = {});

/// The registry entry.
Method sao_method();

}  // namespace aolab
