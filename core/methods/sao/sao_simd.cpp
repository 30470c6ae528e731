// SAO's SIMD path (sao() runs it for Kernel::Simd): the z pyramid laid out for the shared
// SIMD estimator's gathers (ObscuranceLevels: every level in one array, sources only for the
// coarse levels), and the bilateral reconstruction of sao_blur.cpp on Lanes consecutive
// pixels of a row at once (Highway, every target, dispatched at run time). The filter's taps
// in a row lie at fixed offsets from the centre, so they are plain vector loads, no gathers.
// docs/methods/sao.md, "SIMD kernel", gives the tolerances.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/methods/sao/sao_simd.cpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "core/base/parallel.h"
#include "core/base/simd-inl.h"
#include "core/methods/sao/sao_shared.h"

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {

// One output row of a filter pass (sao_blur.cpp's filter_pass): centre values a0 and depths z0
// of the row, and for each tap j the values and depths of its pixels (taps[j], depths[j],
// null where the whole tap lies off the image), each already aligned with the centre row
// (entry x is tap j of pixel x; a tap off the row's ends reads NaN depth). clamp: clamp the
// result to [0, 1] (sao()'s final step, fused into the last pass).
void SaoFilterRow(const float* HWY_RESTRICT a0_row, const float* HWY_RESTRICT z0_row,
                  const float* const* taps, const float* const* depths, const float* gauss,
                  int radius, float inv_edge, int width, bool clamp, float* HWY_RESTRICT out) {
  const DF df;
  const auto zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  const auto v_inv_edge = hn::Set(df, inv_edge);
  ForEachRowVector(df, width, [&](int x0, int count) {
    const auto z0 = LoadRowPart(df, z0_row + x0, count);
    const auto a0 = LoadRowPart(df, a0_row + x0, count);
    auto sum = zero, total = hn::Set(df, gauss[0]);
    for (int k = 0; k < 2 * radius; ++k) {  // j = −radius..−1, 1..radius, the scalar order
      if (!taps[k]) continue;
      const int j = k < radius ? k - radius : k - radius + 1;
      const auto z = LoadRowPart(df, depths[k] + x0, count);
      const auto a = LoadRowPart(df, taps[k] + x0, count);
      const auto edge = hn::Max(zero, hn::NegMulAdd(hn::Abs(hn::Sub(z, z0)), v_inv_edge, one));
      const auto weight = hn::Mul(hn::Set(df, gauss[std::abs(j)]), edge);
      // Background (NaN) never contributes; NaN fails weight > 0 too, but Max may pass it on.
      const auto use = hn::And(hn::Eq(z, z), hn::Gt(weight, zero));
      sum = hn::Add(sum, hn::IfThenElseZero(use, hn::Mul(weight, hn::Sub(a, a0))));
      total = hn::Add(total, hn::IfThenElseZero(use, weight));
    }
    auto result = hn::IfThenElse(hn::Eq(z0, z0), hn::Add(a0, hn::Div(sum, total)), a0);
    if (clamp) result = hn::Min(hn::Max(result, zero), one);
    StoreRowPart(df, result, count, out + x0);
  });
}

}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace aolab {

HWY_EXPORT(SaoFilterRow);

ObscuranceLevels sao_levels_for_simd(std::span<const float> depth, int width, int height,
                                     int max_level, SaoGrid grid, bool with_sources, int threads) {
  // The kernel finds a source's row from a float quotient, exact to ±1 below 2^22 rows.
  if (height >= (1 << 22))
    throw std::invalid_argument("sao: the SIMD kernel takes images of fewer than 2^22 rows");
  ObscuranceLevels lv;
  lv.count = max_level + 1;
  std::vector<int> ws{width}, hs{height};
  std::int64_t total = 0;
  lv.offset.push_back(0);
  for (int m = 1; m <= max_level; ++m) {
    ws.push_back((ws.back() + 1) / 2), hs.push_back((hs.back() + 1) / 2);
    lv.offset.push_back(std::int32_t(total));
    total += std::int64_t(ws.back()) * hs.back();
    if (total > std::numeric_limits<std::int32_t>::max())
      throw std::invalid_argument("sao: image too large for the SIMD kernel's 32-bit indices");
  }
  lv.stride = with_sources ? 2 : 1;
  lv.texels.resize(std::size_t(total) * std::size_t(lv.stride));
  // sao_z_pyramid's rule, level by level (§2.2's rotated grid); level 0 is `depth`.
  const int flip = grid == SaoGrid::Paper ? 1 : 0;
  const std::size_t stride = std::size_t(lv.stride);
  for (int m = 1; m <= max_level; ++m) {
    const int fw = ws[std::size_t(m) - 1], fh = hs[std::size_t(m) - 1];
    const int cw = ws[std::size_t(m)], ch = hs[std::size_t(m)];
    const std::int32_t* fine =
        lv.texels.data() + stride * std::size_t(lv.offset[std::size_t(m) - 1]);
    std::int32_t* out = lv.texels.data() + stride * std::size_t(lv.offset[std::size_t(m)]);
    parallel_for_rows(ch, m == 1 ? threads : 1, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < cw; ++x) {
          const int fx = std::min(2 * x + ((y & 1) ^ flip), fw - 1);
          const int fy = std::min(2 * y + ((x & 1) ^ flip), fh - 1);
          const std::size_t from = std::size_t(fy) * fw + fx;
          std::int32_t* texel = out + stride * (std::size_t(y) * cw + x);
          if (m == 1) {  // from the depth buffer: the source is the pixel itself
            texel[0] = std::bit_cast<std::int32_t>(depth[from]);
            if (with_sources) texel[1] = std::int32_t(from);
          } else {
            for (std::size_t c = 0; c < stride; ++c) texel[c] = fine[stride * from + c];
          }
        }
    });
  }
  return lv;
}

// Columns of the column pass per strip: a multiple of every target's lane count; a strip's
// values, 64 × H floats (180 KiB at H = 720), stay in a core's L2 while it is filtered.
constexpr int kStripColumns = 64;

void sao_bilateral_filter_simd(Image& ao, std::span<const float> depth, const SaoBlurParams& p,
                               int threads, Progress* progress) {
  const int w = ao.width(), h = ao.height();
  std::vector<float> gauss(std::size_t(p.radius) + 1);
  for (int j = 0; j <= p.radius; ++j)
    gauss[std::size_t(j)] = float(std::exp(-double(j) * j / (2.0 * double(p.sigma) * p.sigma)));
  const float inv_edge = p.edge_depth > 0.0f ? 1.0f / p.edge_depth : 0.0f;
  const int reach = p.radius * p.stride;
  const std::size_t padded = std::size_t(w) + 2 * std::size_t(reach);
  const auto tap_offset = [&](int k) { return (k < p.radius ? k - p.radius : k - p.radius + 1); };

  // Both passes work in place, each on a copy of only what it reads (a row; a strip of
  // columns), so that no second image is allocated: fresh pages cost more than the filter.
  // Rows: each row copied into a buffer with `reach` NaN-depth pixels either side, so that a
  // tap's pixels are the centre row shifted by j·stride (off the row: background, skipped).
  parallel_for_rows(
      h, threads,
      [&](int y0, int y1) {
        std::vector<float> a_pad(padded, 0.0f);
        std::vector<float> z_pad(padded, std::numeric_limits<float>::quiet_NaN());
        std::vector<const float*> taps(2 * std::size_t(p.radius)), depths(taps.size());
        for (int y = y0; y < y1; ++y) {
          float* a_row = ao.data() + std::size_t(y) * w;
          const float* z_row = depth.data() + std::size_t(y) * w;
          std::copy(a_row, a_row + w, a_pad.begin() + reach);
          std::copy(z_row, z_row + w, z_pad.begin() + reach);
          for (int k = 0; k < 2 * p.radius; ++k) {
            taps[std::size_t(k)] = a_pad.data() + reach + tap_offset(k) * p.stride;
            depths[std::size_t(k)] = z_pad.data() + reach + tap_offset(k) * p.stride;
          }
          HWY_DYNAMIC_DISPATCH(SaoFilterRow)
          (a_pad.data() + reach, z_row, taps.data(), depths.data(), gauss.data(), p.radius,
           inv_edge, w, false, a_row);
        }
      },
      progress);
  // Columns, in strips of columns: tap j of row y is row y + j·stride of the strip's copy;
  // rows off the image are no taps. Strips are independent, so any thread takes any strip.
  const int strips = (w + kStripColumns - 1) / kStripColumns;
  parallel_for_rows(strips, threads, [&](int s0, int s1) {
    std::vector<float> strip(std::size_t(kStripColumns) * std::size_t(h));
    std::vector<const float*> taps(2 * std::size_t(p.radius)), depths(taps.size());
    for (int s = s0; s < s1; ++s) {
      const int x0 = s * kStripColumns, sw = std::min(kStripColumns, w - x0);
      for (int y = 0; y < h; ++y) {
        const float* from = ao.data() + std::size_t(y) * w + x0;
        std::copy(from, from + sw, strip.begin() + std::ptrdiff_t(y) * sw);
      }
      for (int y = 0; y < h; ++y) {
        for (int k = 0; k < 2 * p.radius; ++k) {
          const int ty = y + tap_offset(k) * p.stride;
          const bool in = ty >= 0 && ty < h;
          taps[std::size_t(k)] = in ? strip.data() + std::size_t(ty) * sw : nullptr;
          depths[std::size_t(k)] = in ? depth.data() + std::size_t(ty) * w + x0 : nullptr;
        }
        HWY_DYNAMIC_DISPATCH(SaoFilterRow)
        (strip.data() + std::size_t(y) * sw, depth.data() + std::size_t(y) * w + x0, taps.data(),
         depths.data(), gauss.data(), p.radius, inv_edge, sw, true,
         ao.data() + std::size_t(y) * w + x0);
      }
    }
  });
  if (progress) {  // the column pass, counted as the rows it filtered
    if (progress->cancel) throw Cancelled();
    progress->done += h;
  }
}

}  // namespace aolab
#endif  // HWY_ONCE
