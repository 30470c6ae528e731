// Separable Gaussian low-pass for AO images, kept apart from the methods so that it can be
// switched and timed on its own (HBAO: optional; Pyramid HBAO §3.5: σ = 1.5, 5 taps).
#pragma once

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/base/settings.h"

namespace aolab {

/// σ = 1.5 px with 5 taps: the filter of the Pyramid HBAO paper (§3.5).
constexpr float kBlurDefaultSigma = 1.5f;
constexpr int kBlurDefaultTaps = 5;

struct BlurSettings {
  /// Standard deviation of the Gaussian, pixels. [0.1, 64].
  float sigma = kBlurDefaultSigma;
  /// Taps per pass (odd: the kernel spans ±taps/2 pixels). [1, 129].
  int taps = kBlurDefaultTaps;
};

inline const SettingField<BlurSettings> kBlurFields[] = {
    {"sigma", &BlurSettings::sigma, 0.1, 64, "px", "standard deviation of the Gaussian"},
    {"taps", &BlurSettings::taps, 1, 129, "", "taps per pass (odd)"},
};

/// Blurs a 1-channel AO image over the valid pixels of `g` in two passes (rows, then
/// columns). Each output is the weighted mean of the valid taps inside the image (weights
/// renormalised), so background never bleeds in; background pixels keep their value.
/// Throws std::invalid_argument for an even or out-of-range `taps`, a bad sigma or a size
/// mismatch.
Image gaussian_blur(ConstImageView ao, const GBuffer& g, const BlurSettings& settings,
                    int threads = 0);

}  // namespace aolab
