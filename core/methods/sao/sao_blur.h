// The reconstruction filter of Scalable Ambient Obscurance (McGuire, Mara, Luebke 2012, §2.4):
// a separable Gaussian, rows then columns, whose taps lie `stride` pixels apart and whose
// weights fall linearly to 0 with the depth difference to the centre.
#pragma once

#include <span>

#include "core/base/image.h"
#include "core/base/parallel.h"

namespace aolab {

struct SaoBlurParams {
  int radius = 4;           ///< taps per side
  int stride = 2;           ///< pixels between taps
  float sigma = 3.0f;       ///< Gaussian σ in taps
  float edge_depth = 0.0f;  ///< depth difference where a tap's weight reaches 0; 0 = no edges
};

/// Filters `ao` (1 channel, W × H) in place over `depth` (W × H, NaN = background): each
/// geometry pixel becomes A_0 + Σ g_j·e_j·(A_j − A_0) / Σ g_j·e_j (the weighted mean) over its taps
/// j = −radius..radius inside the image and on geometry, g_j = exp(−j²/(2σ²)), e_j = max(0, 1 −
/// |z_j − z_0|/edge_depth) (1 when edge_depth is 0 or infinite). Background keeps its value and
/// never contributes. A constant image comes back bit for bit. Rows are counted in `progress` (2
/// passes of H rows).
void sao_bilateral_filter(Image& ao, std::span<const float> depth, const SaoBlurParams& params,
                          int threads, Progress* progress);

}  // namespace aolab
