// The SIMD kernel of VAO++'s cross-bilateral low-pass (bilateral.cpp, the oracle): the same
// taps in the same order on Lanes consecutive pixels of a row, one channel at a time. The taps
// past the
// image's left and right edges read a NaN depth (a padded copy of the row), which fails the
// depth test as the scalar code's bounds test does.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/methods/vao_pp/bilateral_simd.cpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/base/check.h"
#include "core/base/parallel.h"
#include "core/base/simd-inl.h"
#include "core/methods/vao_pp/bilateral.h"
#include "core/methods/vao_pp/vao_pp_shared.h"

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {

// One output row: taps at row offsets (dy = 1) or column offsets (dy = 0). `depth_taps[t]`
// and `value_taps[t]` point at the tap's row shifted so that index x reads the tap of pixel x
// (null: the tap's row is outside the image).
void BilateralRow(const float* HWY_RESTRICT depth_row, const float* HWY_RESTRICT src_row,
                  const float* const* depth_taps, const float* const* value_taps,
                  const float* weights, int taps, int w, float threshold,
                  float* HWY_RESTRICT dst_row) {
  const DF df;
  const VF zero = hn::Zero(df), limit = hn::Set(df, threshold);
  ForEachRowVector(df, w, [&](int x0, int count) {
    const VF dc = LoadRowPart(df, depth_row + x0, count);
    const VF centre = LoadRowPart(df, src_row + x0, count);
    VF sum = zero, wsum = zero;
    for (int t = 0; t < taps; ++t) {
      if (!depth_taps[t]) continue;
      const VF dn = LoadRowPart(df, depth_taps[t] + x0, count);
      const VF vn = LoadRowPart(df, value_taps[t] + x0, count);
      // §4.6: neighbours whose depth differs by more than the threshold are skipped (NaN too).
      const MF ok = hn::Le(hn::Abs(hn::Sub(dn, dc)), limit);
      const VF wt = hn::IfThenElseZero(ok, hn::Set(df, weights[t]));
      sum = hn::MulAdd(wt, vn, sum);
      wsum = hn::Add(wsum, wt);
    }
    const MF geometry = hn::Eq(dc, dc);
    const VF filtered = hn::Div(sum, hn::IfThenElse(geometry, wsum, hn::Set(df, 1.0f)));
    StoreRowPart(df, hn::IfThenElse(geometry, filtered, centre), count, dst_row + x0);
  });
}

}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace aolab {

HWY_EXPORT(BilateralRow);

// Rows per band: the row pass is made again for `half` rows either side of a band, so bands
// much taller than the filter keep that share small (1 tap in 32 at 3 taps).
constexpr int kBilateralBandRows = 32;

Image cross_bilateral_filter_simd(ConstImageView image, const GBuffer& g, int taps, float sigma,
                                  float depth_threshold, int threads, Progress* progress) {
  require_same_size("depth", g.depth, "image", image);
  return cross_bilateral_filter_simd(image, depth_with_background_as_nan(g, threads).data(), taps,
                                     sigma, depth_threshold, threads, progress);
}

Image cross_bilateral_filter_simd(ConstImageView image, const float* depth, int taps, float sigma,
                                  float depth_threshold, int threads, Progress* progress) {
  if (taps < 1 || taps % 2 == 0) throw_invalid("taps", "must be an odd number >= 1", taps);
  if (!(sigma > 0.0f) || !std::isfinite(sigma)) throw_invalid("sigma", "must be > 0", sigma);
  if (!(depth_threshold >= 0.0f)) throw_invalid("depth_threshold", "must be >= 0", depth_threshold);
  const int w = image.width, h = image.height, nc = image.channels, half = taps / 2;
  if (nc != 1) {
    // The taps' weights depend on depth alone: each channel is filtered as an image of its own,
    // so that a channel's result does not depend on the others'.
    Image out(w, h, nc);
    for (int c = 0; c < nc; ++c) {
      Image plane(w, h);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) plane(x, y) = image(x, y, c);
      const Image filtered = cross_bilateral_filter_simd(plane.view(), depth, taps, sigma,
                                                         depth_threshold, threads, progress);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) out(x, y, c) = filtered(x, y);
    }
    return out;
  }
  std::vector<float> weights(static_cast<std::size_t>(taps));
  for (int i = -half; i <= half; ++i)
    weights[std::size_t(i + half)] = std::exp(-0.5f * float(i * i) / (sigma * sigma));
  const float nan = std::numeric_limits<float>::quiet_NaN();

  Image out(w, h);
  if (progress) progress->total += h;
  // Per band: the row pass of the band's rows and `half` rows either side into a buffer of the
  // band's own (no image-sized intermediate, and it stays in cache), then the column pass.
  parallel_for_rows(
      h, threads,
      [&](int y0, int y1) {
        const int r0 = std::max(0, y0 - half), r1 = std::min(h, y1 + half);
        std::vector<float> rows(std::size_t(r1 - r0) * w);
        std::vector<float> depth_pad(std::size_t(w + 2 * half), nan);
        std::vector<float> value_pad(std::size_t(w + 2 * half), 0.0f);
        std::vector<const float*> depth_taps(static_cast<std::size_t>(taps)),
            value_taps(static_cast<std::size_t>(taps));
        for (int y = r0; y < r1; ++y) {  // taps along x, from copies padded by `half`
          const float* depth_row = depth + std::size_t(y) * w;
          const float* src_row = image.data + std::size_t(y) * image.row_stride;
          std::copy(depth_row, depth_row + w, depth_pad.begin() + half);
          std::copy(src_row, src_row + w, value_pad.begin() + half);
          for (int t = 0; t < taps; ++t) {
            depth_taps[std::size_t(t)] = depth_pad.data() + t;
            value_taps[std::size_t(t)] = value_pad.data() + t;
          }
          HWY_DYNAMIC_DISPATCH(BilateralRow)
          (depth_row, src_row, depth_taps.data(), value_taps.data(), weights.data(), taps, w,
           depth_threshold, rows.data() + std::size_t(y - r0) * w);
        }
        for (int y = y0; y < y1; ++y) {  // taps along y, rows outside the image left out
          for (int t = 0; t < taps; ++t) {
            const int yy = y + t - half;
            const bool inside = yy >= 0 && yy < h;
            depth_taps[std::size_t(t)] = inside ? depth + std::size_t(yy) * w : nullptr;
            value_taps[std::size_t(t)] = inside ? rows.data() + std::size_t(yy - r0) * w : nullptr;
          }
          HWY_DYNAMIC_DISPATCH(BilateralRow)
          (depth + std::size_t(y) * w, rows.data() + std::size_t(y - r0) * w, depth_taps.data(),
           value_taps.data(), weights.data(), taps, w, depth_threshold, &out(0, y));
        }
      },
      progress, kBilateralBandRows);
  return out;
}

}  // namespace aolab
#endif  // HWY_ONCE
