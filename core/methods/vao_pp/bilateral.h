// The cross-bilateral low-pass of VAO++ (Bokšanský et al. 2017, §4.6): a Gaussian whose taps
// skip neighbours whose view-space depth differs from the centre's by more than a threshold
// (the AO radius), run in two passes (rows, then columns) "as if the filter was separable
// (though technically it is not)".
#pragma once

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/parallel.h"

namespace aolab {

/// Filters every channel of `image` (the size of g) over the valid pixels of `g`: each output
/// is the weighted mean, Gaussian weights exp(-i²/(2σ²)) renormalised, of the taps i in
/// [-taps/2, taps/2] that are inside the image, valid and within `depth_threshold` of the
/// centre's depth (the centre always is). Rows first, then columns. Background pixels keep
/// their value and never contribute. A constant image comes back bit for bit.
/// Throws std::invalid_argument naming `taps` (even or < 1), `sigma` (not > 0),
/// `depth_threshold` (NaN or < 0) or `image` (size).
Image cross_bilateral_filter(ConstImageView image, const GBuffer& g, int taps, float sigma,
                             float depth_threshold, int threads = 0, Progress* progress = nullptr);

}  // namespace aolab
