// Structural similarity (SSIM) of Wang, Bovik, Sheikh and Simoncelli, "Image quality assessment:
// from error visibility to structural similarity", IEEE TIP 13(4), 2004 — with the Gaussian
// window they recommend, computed exactly as scikit-image's structural_similarity(...,
// gaussian_weights=True, sigma=1.5, use_sample_covariance=False, data_range=1) does, so that
// numbers in our reports can be compared with numbers computed by anyone with scikit-image
// (tests/python/api/test_metrics.py checks the agreement to 1e-4).
//
// Principles: images are 1-channel AO in [0, 1] (data range 1); all statistics are accumulated
// in double; rows are filtered in parallel but every pixel is computed by the same code in the
// same order, so results are bit-identical for any thread count. Bad input throws
// std::invalid_argument naming the parameter and the value.
#pragma once

#include "core/base/image.h"

namespace aolab {

/// Standard deviation of the Gaussian window, pixels: Wang et al. 2004 weight their 11 × 11
/// window with a circular-symmetric Gaussian of standard deviation 1.5 samples.
inline constexpr double kSsimDefaultSigma = 1.5;
/// Window half-width in units of sigma. scikit-image picks 3.5 so that the radius
/// int(3.5 · 1.5 + 0.5) = 5 gives Wang et al.'s 11 × 11 window (the Pyramid HBAO paper's too).
inline constexpr double kSsimDefaultTruncate = 3.5;
/// Wang et al. 2004's K1 = 0.01: small enough not to matter where the means are not
/// both near zero, large enough to keep the luminance term stable on black patches.
inline constexpr double kSsimDefaultK1 = 0.01;
/// Wang et al. 2004's K2 = 0.03: the same role for the contrast-structure term on flat
/// patches (which AO images are full of).
inline constexpr double kSsimDefaultK2 = 0.03;
/// AO values lie in [0, 1], so Wang et al.'s dynamic range L (in C1 = (K1 L)², C2 = (K2 L)²)
/// is 1.
inline constexpr double kSsimDefaultDataRange = 1.0;

/// Settings of SSIM. The defaults are those of Wang et al. 2004 and must not be changed for
/// reported numbers; they exist as fields so that tests and studies can vary them explicitly.
struct SsimSettings {
  /// Gaussian window standard deviation, pixels; > 0 (default 1.5).
  double sigma = kSsimDefaultSigma;
  /// Window radius in sigmas, > 0; radius = int(truncate · sigma + 0.5) pixels, as in
  /// scipy.ndimage.gaussian_filter (default 3.5 → radius 5, an 11 × 11 window).
  double truncate = kSsimDefaultTruncate;
  /// Luminance stabiliser K1, dimensionless, > 0; C1 = (K1 · L)² (default 0.01).
  double k1 = kSsimDefaultK1;
  /// Contrast stabiliser K2, dimensionless, > 0; C2 = (K2 · L)² (default 0.03).
  double k2 = kSsimDefaultK2;
  /// Data range L, AO units, > 0: the span of possible values (default 1 for AO in [0, 1]).
  double data_range = kSsimDefaultDataRange;
};

/// Constants derived once from SsimSettings (XeGTAO's GTAOUpdateConstants habit).
struct SsimConstants {
  int radius = 0;  ///< window radius, pixels: int(truncate · sigma + 0.5)
  double c1 = 0;   ///< (K1 · L)²
  double c2 = 0;   ///< (K2 · L)²
};

/// Validates `settings` (throws std::invalid_argument naming the field) and derives the
/// constants.
SsimConstants ssim_constants(const SsimSettings& settings);

/// The SSIM map S of Wang et al. 2004 eq. (13),
///   S = ((2 μa μb + C1)(2 σab + C2)) / ((μa² + μb² + C1)(σa² + σb² + C2)),
/// with μ, σ², σab the Gaussian-weighted means, population variances and covariance of
/// eqs. (14)–(16). The weights are exp(−x² / 2σ²) for integer x in [−radius, radius], normalised
/// to unit sum, applied separably; outside the image it uses scipy's 'reflect' extension
/// (half-sample symmetric: d c b a | a b c d | d c b a, repeated for images narrower than the
/// window). `a` and `b` are 1-channel images of the same size with finite values (a NaN or
/// infinity is std::invalid_argument naming the image and the pixel); the result is
/// 1 channel, the size of `a`, −1 ≤ S ≤ 1, symmetric in a and b, and 1 where a = b.
/// It is accurate for any finite float input, however large: where E[a²] − E[a]² would cancel
/// (values large against their spread in the window, e.g. a constant 1e20) the pixel's moments
/// are recomputed relative to the window's centre value, so SSIM(+1e20, −1e20) is −1, not 1.
/// AO in [0, 1] never needs that and gets the same bits as scikit-image's formula.
/// `threads` = 0 uses all cores; the result does not depend on it.
Image ssim_map(ConstImageView a, ConstImageView b, const SsimSettings& settings = {},
               int threads = 0);

/// Mean SSIM (Wang et al. 2004 eq. (17)) over the interior of the image — S cropped by the
/// window radius (5 px by default) on every side, as scikit-image does, because near the border
/// the window reads reflected pixels.
///
/// `mask` (1 channel, size of `a`; empty view = every pixel) selects the scored pixels by a
/// non-zero value. Before filtering, both images are set to 1 (the AO of background) outside
/// the mask, so background contributes no spurious structure; then S is averaged over the
/// pixels that are masked and in the interior. If no masked pixel lies in the interior (in
/// particular when the image is smaller than 2 · radius + 1 = 11 px in a dimension, where
/// scikit-image refuses to compute), S is averaged over all masked pixels instead.
/// Throws std::invalid_argument if the mask selects no pixel or if `a` or `b` is not finite on
/// a masked pixel. Accumulated in double, rows summed in order: deterministic.
double mean_ssim(ConstImageView a, ConstImageView b, ConstImageView mask = {},
                 const SsimSettings& settings = {}, int threads = 0);

}  // namespace aolab
