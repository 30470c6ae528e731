// VAO++: Bokšanský, Pospíšil, Bittner, "VAO++: Practical Volumetric Ambient Occlusion for
// Games", EGSR 2017, §4: VAO (core/methods/vao/vao.h; its per-sample code, which VAO++ runs,
// is core/volumetric/pipes.h) with these extensions, each a setting:
//   §4.1 adaptive sampling: 2, 4, 8, 16 or 32 samples from the projected disc area;
//   §4.2 culling pre-pass: AO at 1/8 resolution with 8 samples; pixels with no occlusion in
//        the bilinear fetches at their four corners are skipped (greedy) or get 4 samples
//        (careful);
//   §4.3 luminance sensitivity (eq. 3), §4.4 depth range check (eq. 4), §4.5 rotation-aware
//        Poisson-disk sets in 3×3 tiles (core/sampling/poisson_disk.h), §4.6 the cross-bilateral
//        low-pass in two passes (core/methods/vao_pp/bilateral.h), §4.7 colour bleeding (eq. 5, RGB
//        result).
// The passes run as in §3: occlusion (after the culling pre-pass), low-pass filter, then the
// luminance correction and the colour product. docs/methods/vao_pp.md.
#pragma once

#include <cstdint>

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/settings.h"
#include "core/methods/registry.h"
#include "core/volumetric/pipes.h"

namespace aolab {

/// §4.1: "precomputed sample sets with 2, 4, 8, 16 or 32 samples".
constexpr int kVaoPpMinSamples = 2;
constexpr int kVaoPpMaxSamples = 32;
/// §4.2: "we use 1/8 resolution of the final image", "always use 8 samples for this pass",
/// careful culling "calculates occlusion with 4 samples".
constexpr int kVaoPpCullFactor = 8;
constexpr int kVaoPpCullSamples = 8;
constexpr int kVaoPpCarefulSamples = 4;
/// A fetch "exhibits occlusion" below this: the smallest occlusion an 8-bit AO texture (the
/// paper's GPU target) shows, half a step below 255/255.
constexpr float kVaoPpCullThreshold = 1.0f - 0.5f / 255.0f;
/// §4.1 leaves the diameter to the user: 1 % of the image height gets 2 samples, so a disc of
/// 4 % (43 px at 1080p) gets 32: about one sample per 45 px² at every distance.
constexpr float kVaoPpAdaptiveMinDiameter = 0.01f;
/// Eq. 3's profile. Figure 9 uses threshold 0.5, width 0.3; lum here is the unit-ambient
/// radiance colour + emission (docs), where albedos reach 1, so the default threshold puts
/// the ramp [threshold - width, threshold + width] = [1, 1.6] above every albedo: only
/// emissive surfaces lose their AO.
constexpr float kVaoPpLuminanceThreshold = 1.3f;
constexpr float kVaoPpLuminanceWidth = 0.3f;
constexpr float kVaoPpLuminanceSigma = 1.0f;
/// §4.6 "fast low-pass filter of matching size" for the 3×3 tile: 3 taps; σ = 4 px makes it
/// nearly a box (outer weights 0.97), so the nine rotations of a tile weigh almost alike.
constexpr int kVaoPpFilterTaps = 3;
constexpr float kVaoPpFilterSigma = 4.0f;

enum class VaoPpCulling { Off = 0, Greedy = 1, Careful = 2 };

struct VaoPpSettings {
  /// R: radius of influence in view-space units; the tangent sphere has radius R/2.
  /// [1e-12, 1e30].
  float radius = 1.0f;
  /// Samples per pixel; with adaptive sampling the most any pixel gets. One of 2, 4, 8, 16,
  /// 32 (§4.1). [2, 32].
  int samples = kVaoDefaultSamples;
  /// Pipes along the samples' view rays (exact on planes); off: parallel to the view axis
  /// with F by eq. 2 (as VaoSettings::view_ray_pipes, vao.h).
  bool view_ray_pipes = true;
  /// §4.1: fewer samples where the projected disc is small.
  bool adaptive_sampling = true;
  /// §4.1: the disc diameter, as a fraction of the image height, that gets 2 samples; the
  /// count doubles whenever the disc's area doubles. [1e-6, 10].
  float adaptive_min_diameter = kVaoPpAdaptiveMinDiameter;
  /// §4.2: 0 = no pre-pass, 1 = greedy (culled pixels are 1), 2 = careful (culled pixels get
  /// 4 samples; the paper's default). [0, 2].
  int culling = int(VaoPpCulling::Careful);
  /// §4.2: a bilinear fetch of the 1/8-resolution AO below this "exhibits occlusion". [0, 1].
  float cull_threshold = kVaoPpCullThreshold;
  /// §4.3 eq. 3: suppress AO on bright (emissive) surfaces. Reads colour (and emission).
  bool luminance_sensitivity = false;
  /// Eq. 3's threshold, in lum units (unit-ambient radiance). [0, 1e30].
  float luminance_threshold = kVaoPpLuminanceThreshold;
  /// Eq. 3's width: the correction ramps over [threshold - width, threshold + width].
  /// [1e-6, 1e30].
  float luminance_width = kVaoPpLuminanceWidth;
  /// Eq. 3's σ, the exponent of the profile. [0.001, 1000].
  float luminance_sigma = kVaoPpLuminanceSigma;
  /// §4.3: 0 = luminance (Rec. 709 weights), 1 = the V of HSV (max of R, G, B). [0, 1].
  int luminance_mode = 0;
  /// §4.4 eq. 4: occluders are thin, occlusion fades with the depth behind them.
  bool range_check = true;
  /// §4.5: rotation-aware Poisson-disk sets rotated in 3×3 tiles; off: VAO's spiral set with a
  /// random rotation per pixel.
  bool poisson_samples = true;
  /// §4.6: the cross-bilateral low-pass (depth threshold R), two passes.
  bool filter = true;
  /// §4.6: taps per pass (odd). [1, 63].
  int filter_taps = kVaoPpFilterTaps;
  /// §4.6: σ of the Gaussian, pixels. [0.1, 1000].
  float filter_sigma = kVaoPpFilterSigma;
  /// §4.7 eq. 5: colour bleeding; the result is RGB (3 channels). Reads colour.
  bool color_bleeding = false;
  /// §4.7: every k-th sample gathers colour (1, 2 or 4). [1, 4].
  int bleeding_sample_step = 1;
  /// Seed: rotates the whole sample pattern (Poisson sets) or the per-pixel random rotations
  /// (spiral set). 0 = no extra rotation. [0, 2^31 - 1].
  int seed = 0;
};

inline const SettingField<VaoPpSettings> kVaoPpFields[] = {
    {"radius", &VaoPpSettings::radius, 1e-12, 1e30, "view-space units",
     "R, radius of influence; the tangent sphere has radius R/2"},
    {"samples", &VaoPpSettings::samples, 2, 32, "",
     "samples per pixel (the most, with adaptive sampling): 2, 4, 8, 16 or 32"},
    {"view_ray_pipes", &VaoPpSettings::view_ray_pipes, 0, 1, "",
     "pipes along the view rays of the samples' texels (exact on planes); off: parallel to "
     "the view axis, F by eq. 2"},
    {"adaptive_sampling", &VaoPpSettings::adaptive_sampling, 0, 1, "",
     "fewer samples where the projected disc is small (4.1)"},
    {"adaptive_min_diameter", &VaoPpSettings::adaptive_min_diameter, 1e-6, 10, "image heights",
     "projected disc diameter that gets 2 samples (4.1)"},
    {"culling", &VaoPpSettings::culling, 0, 2, "",
     "culling pre-pass (4.2): off; greedy (culled pixels are 1); careful (culled pixels get 4 "
     "samples)",
     "off|greedy|careful"},
    {"cull_threshold", &VaoPpSettings::cull_threshold, 0, 1, "",
     "a 1/8-resolution AO fetch below this exhibits occlusion (4.2)"},
    {"luminance_sensitivity", &VaoPpSettings::luminance_sensitivity, 0, 1, "",
     "suppress AO on bright surfaces, eq. 3 (reads color and emission)"},
    {"luminance_threshold", &VaoPpSettings::luminance_threshold, 0, 1e30, "", "threshold of eq. 3"},
    {"luminance_width", &VaoPpSettings::luminance_width, 1e-6, 1e30, "", "width of eq. 3"},
    {"luminance_sigma", &VaoPpSettings::luminance_sigma, 0.001, 1000, "", "sigma of eq. 3"},
    {"luminance_mode", &VaoPpSettings::luminance_mode, 0, 1, "",
     "lum(x) of eq. 3: luminance (Rec. 709 weights) or the HSV value (max of R, G, B)",
     "luminance|value"},
    {"range_check", &VaoPpSettings::range_check, 0, 1, "",
     "depth range check, s(d) = u/max(u, d/R), u = 0.03 (4.4)"},
    {"poisson_samples", &VaoPpSettings::poisson_samples, 0, 1, "",
     "rotation-aware Poisson-disk sets in 3x3 tiles (4.5); off: spiral, random rotation"},
    {"filter", &VaoPpSettings::filter, 0, 1, "", "cross-bilateral low-pass, two passes (4.6)"},
    {"filter_taps", &VaoPpSettings::filter_taps, 1, 63, "", "taps per filter pass (odd)"},
    {"filter_sigma", &VaoPpSettings::filter_sigma, 0.1, 1000, "px", "sigma of the filter"},
    {"color_bleeding", &VaoPpSettings::color_bleeding, 0, 1, "",
     "colour bleeding, eq. 5: RGB result (reads color)"},
    {"bleeding_sample_step", &VaoPpSettings::bleeding_sample_step, 1, 4, "",
     "every k-th sample gathers colour: 1, 2 or 4 (4.7)"},
    {"seed", &VaoPpSettings::seed, 0, 2147483647, "", "rotates the sample pattern; 0 = none"},
};

/// What a run did, for the culling and adaptive-sampling studies.
struct VaoPpStats {
  std::int64_t pixels = 0;          ///< geometry pixels
  std::int64_t culled = 0;          ///< culling candidates (greedy: set to 1; careful: 4 samples)
  std::int64_t samples = 0;         ///< samples evaluated in the full-resolution pass
  std::int64_t prepass_pixels = 0;  ///< 1/8-resolution pixels evaluated (8 samples each)
  /// culled / pixels (0 without geometry).
  double culled_share() const { return pixels ? double(culled) / double(pixels) : 0.0; }
  /// samples / pixels (0 without geometry).
  double mean_samples() const { return pixels ? double(samples) / double(pixels) : 0.0; }
};

/// VAO++ of a G-buffer with normals (and colour for luminance sensitivity or colour
/// bleeding; emission is optional). Returns a 1-channel image in [0, 1], or with colour
/// bleeding 3 channels A_L·B (docs); background = 1. Fills `stats` if given.
/// Throws std::invalid_argument naming the setting for invalid settings (samples not a power
/// of two, even filter_taps, bleeding_sample_step 3), `normal` or `color` when missing;
/// Cancelled if cancelled.
Image vao_pp(const GBuffer& g, const VaoPpSettings& settings, const RunOptions& options = {},
             VaoPpStats* stats = nullptr);

/// The registry entry (needs_color: may read colour; color_depends_on_settings: vao_pp()
/// checks when).
Method vao_pp_method();

/// The factor eq. 3 multiplies the occlusion 1 - A by: (1 - t)^σ with
/// t = clamp((lum - threshold + width)/(2·width), 0, 1).
float vao_pp_luminance_factor(float lum, float threshold, float width, float sigma);

/// lum(x) of §4.3 from the surface's unit-ambient radiance rgb: mode 0 = Rec. 709 luminance
/// 0.2126 R + 0.7152 G + 0.0722 B, mode 1 = HSV value max(R, G, B).
float vao_pp_lum(const float rgb[3], int mode);

/// §4.1: samples for a disc of projected diameter `diameter` (fraction of the image height):
/// 2 up to `min_diameter`, doubled each time the area doubles, at most `max_samples`.
int vao_pp_adaptive_samples(float diameter, float min_diameter, int max_samples);

}  // namespace aolab
