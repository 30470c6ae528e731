// Chebyshev ambient occlusion: Ka-Hou Chan, Sio-Kei Im, "Chebyshev Ambient Occlusion",
// IEEE Access 9, 2021 (doi:10.1109/ACCESS.2021.3124008). docs/methods/chebyshev.md gives the
// details.
//
// Depth only. Over a k×k window around each pixel the first two moments of depth give μ and
// σ² (§III: M1 = E(x), M2 = E(x²), two perpendicular box passes, O(2k)); the one-sided
// Chebyshev (Cantelli) bound of eq. 2, with the variance bias ε of §III-A and the one-sided
// comparison of eq. 3 (§III-B), is the visibility:
//
//   A = (σ² + ε) / ((σ² + ε) + max(d − μ, 0)²)                       (eq. 3)
//
// written for our planar depth d > 0 (the paper's eq. 3 reads max(μ − d, 0) in OpenGL's view
// z, which is negative and grows towards the eye: the receiver is occluded when it lies
// behind the mean of its neighbourhood). §III-C's range check fades occlusion whose mean
// depth gap d − μ exceeds R. The window half-width is R·fx/d pixels (k ∝ 1/d, §III) or a
// fixed pixel count, always symmetric about the pixel and clamped to the image; ε = b·R².
//
// Moments are taken relative to local references (the horizontal pass about the window's
// column pixel, the vertical pass shifted exactly onto the receiver's depth), so σ² never
// suffers the cancellation of M2 − M1² at large depths; background pixels are left out of
// the window and counted (the moments are means over the valid pixels).
// Units: view space, planar depth (docs/conventions.md). Errors: std::invalid_argument naming
// the setting. Threads: fixed row bands; bit-identical for any thread count.
#pragma once

#include <vector>

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/settings.h"
#include "core/methods/registry.h"

namespace aolab {

/// ε = b·R² with b = 1e-4: the paper asks only for "a bias" (§III-A). Relative to R² so the
/// result depends on geometry relative to R alone (any depth scale); 1e-4 suppresses relief
/// below about 1 % of R (σ below √b·R), far below what the reference scenes resolve, and
/// keeps σ² + ε > 0 on any surface facing the camera.
constexpr float kChebyshevDefaultVarianceBias = 1e-4f;

/// Fixed-kernel mode: the paper's k = 2·8 + 1 = 17 pixels (no value is given; 17 is a
/// typical blur size at 720p).
constexpr int kChebyshevDefaultKernelRadius = 8;

/// Depth-adaptive mode clamp: half-widths above 64 px (a 129-pixel window) cost more than
/// the whole rest of a frame and are beyond what screen-space AO should reach at 720p.
constexpr int kChebyshevDefaultMaxKernelRadius = 64;

/// Half-widths are quantised so that the two passes can be shared by all pixels of one
/// width: every integer up to kChebyshevExactLevels pixels (steps ≤ 6 %), then
/// kChebyshevLevelsPerOctave geometric steps per doubling (16, 19, 23, 27, 32, 38, …; within
/// ±10 % of R·fx/d). At most ~40 widths occur in a frame.
constexpr int kChebyshevExactLevels = 16;
constexpr int kChebyshevLevelsPerOctave = 4;

/// A mean gap d − μ below this fraction of the RMS offset √E((x − d)²) is rounding, not
/// occlusion: it changes A by < 1e-8 (below float resolution at 1), and the rounding of the
/// float window sums stays below it for windows up to 129² pixels ((2r + 1)·2·2^-24 ≈ 1.5e-5).
/// A plane (whose planar depth is convex in the image, so d ≤ μ over a symmetric window) thus
/// gives exactly 1.
constexpr double kChebyshevMeanTolerance = 1e-4;

/// How the window size is chosen (§III: "this k should be adjusted according to the current
/// d, as k ∝ 1/d").
enum class ChebyshevKernel : int {
  Fixed = 0,     ///< k = 2·kernel_radius + 1 pixels everywhere (the paper's constant k)
  Adaptive = 1,  ///< half-width R·fx/d pixels (R·fy/d vertically): R in view space
};

struct ChebyshevSettings {
  /// R: view-space scale of the effect. Adaptive mode: the window half-width is R·fx/d px.
  /// Both modes: ε = variance_bias·R², and the range check fades gaps beyond R.
  /// [1e-12, 1e30] view-space units.
  float radius = 1.0f;
  /// ChebyshevKernel: 0 = fixed pixel window, 1 = depth-adaptive (k ∝ 1/d). [0, 1].
  int kernel_mode = int(ChebyshevKernel::Adaptive);
  /// Fixed mode: window half-width, pixels (k = 2·kernel_radius + 1; 0 = off). [0, 1024].
  int kernel_radius = kChebyshevDefaultKernelRadius;
  /// Adaptive mode: largest half-width, pixels. [0, 1024].
  int max_kernel_radius = kChebyshevDefaultMaxKernelRadius;
  /// b of ε = b·R² (§III-A's bias on the variance), dimensionless. [0, 1e6].
  float variance_bias = kChebyshevDefaultVarianceBias;
  /// §III-B, eq. 3: only pixels behind the mean (d > μ) are occluded. false: eq. 2 with
  /// (d − μ)² (Figure 2e: outlines on both sides of depth edges).
  bool ignore_unoccluded = true;
  /// §III-C: scale the occlusion 1 − P by smoothstep(0, 1, R/|d − μ|), so occluders much more
  /// than R in front do not count.
  bool range_check = true;
  /// Background never enters the moments. true: each window shrinks (symmetrically, to a
  /// level below the chessboard distance to the nearest background pixel) so that it holds
  /// none; a plane ending at background stays exactly 1. false: background pixels in the
  /// window are skipped and the moments averaged over the rest, which biases μ towards the
  /// visible side at silhouettes (a plane's far edge against the sky darkens).
  bool shrink_at_background = true;
};

inline const SettingField<ChebyshevSettings> kChebyshevFields[] = {
    {"radius", &ChebyshevSettings::radius, 1e-12, 1e30, "view-space units",
     "R; adaptive window half-width R fx/d px, epsilon = variance_bias R^2, range-check scale"},
    {"kernel_mode", &ChebyshevSettings::kernel_mode, 0, 1, "",
     "fixed: a pixel window of constant size; adaptive: half-width R fx/d (k proportional to 1/d)",
     "fixed|adaptive"},
    {"kernel_radius", &ChebyshevSettings::kernel_radius, 0, 1024, "px",
     "fixed mode: window half-width (k = 2 kernel_radius + 1)"},
    {"max_kernel_radius", &ChebyshevSettings::max_kernel_radius, 0, 1024, "px",
     "adaptive mode: largest window half-width"},
    {"variance_bias", &ChebyshevSettings::variance_bias, 0, 1e6, "",
     "b of the variance bias epsilon = b R^2"},
    {"ignore_unoccluded", &ChebyshevSettings::ignore_unoccluded, 0, 1, "",
     "eq. 3, max(d - mu, 0): only pixels behind the mean are occluded; off: eq. 2"},
    {"range_check", &ChebyshevSettings::range_check, 0, 1, "",
     "fade occlusion by smoothstep(0, 1, R/gap), gap = d - mu (abs for eq. 2)"},
    {"shrink_at_background", &ChebyshevSettings::shrink_at_background, 0, 1, "",
     "shrink each window to hold no background; off: skip background pixels in the window"},
};

/// Chebyshev AO of a G-buffer; reads depth only. Returns a 1-channel image in [0, 1];
/// background = 1. Throws std::invalid_argument for invalid settings or G-buffer; Cancelled
/// if cancelled.
Image chebyshev(const GBuffer& g, const ChebyshevSettings& settings,
                const RunOptions& options = {});

/// The registry entry.
Method chebyshev_method();

/// Window moments per pixel (3 channels): the count n of valid pixels in the window, the mean
/// gap λ = d − μ and the variance σ² ≥ 0; background pixels get (0, 0, 0). Computed in the
/// two passes described above; exposed for tests.
Image chebyshev_moments(const GBuffer& g, const ChebyshevSettings& settings,
                        const RunOptions& options = {});

/// Visibility from the moments (eq. 3 or 2, bias, range check), in [0, 1].
float chebyshev_visibility(float gap, float variance, const ChebyshevSettings& s);

/// The quantised horizontal window half-width for an exact half-width r (pixels), capped at
/// `cap`: 0 below 0.5, round(r) up to kChebyshevExactLevels, then the nearest (in ratio) of
/// the geometric levels, kChebyshevLevelsPerOctave per octave.
int chebyshev_quantised_radius(double r, int cap);

/// The largest quantised half-width ≤ r (r ≥ 0): the width a window shrinks to.
int chebyshev_level_below(int r);

}  // namespace aolab
