// Accuracy of an AO image against a reference (docs/comparison.md, "Accuracy and its cost";
// definitions in docs/metrics.md): MAE, RMSE, PSNR, signed bias and mean SSIM over the scored
// pixels.
//
// Principles: AO is 1-channel accessibility in [0, 1], so every metric uses data range 1.
// Background pixels are excluded by a mask (non-zero = scored). Sums are taken in double, one
// per row, then the rows in order, so the result has the same bits for any thread count.
// Bad input throws std::invalid_argument naming the parameter and its value.
#pragma once

#include <cstdint>
#include <string>

#include "core/base/image.h"

namespace aolab {

/// Accuracy of an AO image against its reference over the scored pixels.
struct Metrics {
  double mae = 0;   ///< mean |ao − reference|, AO units, ≥ 0
  double rmse = 0;  ///< sqrt(mean (ao − reference)²), AO units, ≥ 0
  /// 10 · log10(1 / MSE), dB, data range 1; +infinity when the images agree exactly (MSE = 0).
  double psnr = 0;
  /// mean (ao − reference), AO units, in [−1, 1]. Positive = the method is brighter than the
  /// reference = under-occlusion; negative = darker = over-occlusion.
  double bias = 0;
  double ssim = 0;  ///< mean SSIM (see mean_ssim in core/scoring/ssim.h), ≤ 1, 1 = identical
  std::int64_t count = 0;  ///< number of scored pixels, ≥ 1
};

/// Metrics of `ao` against `reference` over the pixels where `mask` is non-zero (an empty view
/// scores every pixel; NaN counts as non-zero). All three are 1-channel images of the same size,
/// otherwise std::invalid_argument names `ao`, `reference` or `mask`. Throws if the mask
/// selects no pixel, or if `ao` or `reference` is not finite on a scored pixel (naming the
/// first such pixel in row-major order and its value). SSIM is mean_ssim(ao, reference, mask)
/// with the default SsimSettings. `threads` = 0 uses all cores; the result does not depend
/// on it.
Metrics compute_metrics(ConstImageView ao, ConstImageView reference, ConstImageView mask = {},
                        int threads = 0);

/// Throws std::invalid_argument naming `name` unless `image` (1 channel) is finite on every
/// pixel selected by `mask` (non-zero; empty view = all pixels). The message gives the first
/// non-finite pixel in row-major order, its (x, y) and its value. `mask`, if not empty, must
/// have the size of `image`.
void require_finite(const std::string& name, ConstImageView image, ConstImageView mask = {},
                    int threads = 0);

/// The inputs of a comparison: throws std::invalid_argument naming the offending image
/// unless `a` and `b` are non-empty 1-channel images of one size, `mask` (if not empty) is a
/// 1-channel image of that size, and both are finite on every pixel the mask selects.
void require_comparable(const std::string& name_a, ConstImageView a, const std::string& name_b,
                        ConstImageView b, ConstImageView mask = {}, int threads = 0);

}  // namespace aolab
