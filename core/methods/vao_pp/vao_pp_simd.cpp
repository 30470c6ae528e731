// VAO++'s SIMD kernel: the culling pre-pass (§4.2) and the occlusion pass (§3) of vao_pp.cpp
// on VAO's SIMD sample loop (vao_simd_span, core/volumetric/pipes_simd.cpp), in tiles of rows; the
// cross-bilateral filter's SIMD form is bilateral_simd.cpp. vao_pp() runs them for Kernel::Simd;
// the scalar passes are their oracle (docs/methods/vao_pp.md).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include "core/base/parallel.h"
#include "core/base/simd_tiles.h"
#include "core/methods/vao_pp/vao_pp_shared.h"
#include "core/volumetric/pipes_simd.h"

namespace aolab::vao_pp_detail {

namespace {

// occlusion_nearby's four fetches (vao_pp.cpp), made once per corner of the pixel grid:
// corner (x, y) "exhibits occlusion" (the same arithmetic, so the same decisions). What
// depends on x alone (the texel columns and the weight tu) is made once per run.
struct CornerColumns {
  std::vector<int> i0, i1;  // the clamped texel columns of u = x/8 − 0.5
  std::vector<float> tu;
  CornerColumns(int w, int lw) {
    for (int x = 0; x <= w; ++x) {
      const float u = float(x) / float(kVaoPpCullFactor) - 0.5f;
      const float fu = std::floor(u);
      const int i = int(fu);
      i0.push_back(std::clamp(i, 0, lw - 1));
      i1.push_back(std::clamp(i + 1, 0, lw - 1));
      tu.push_back(u - fu);
    }
  }
};

void occluded_corners(const Image& low, const CornerColumns& cols, int y, int w, float threshold,
                      std::vector<char>& out) {
  const int lh = low.height();
  const float v = float(y) / float(kVaoPpCullFactor) - 0.5f;
  const float fv = std::floor(v);
  const int j = int(fv);
  const float tv = v - fv;
  const float* row0 = low.data() + std::size_t(std::clamp(j, 0, lh - 1)) * low.width();
  const float* row1 = low.data() + std::size_t(std::clamp(j + 1, 0, lh - 1)) * low.width();
  out.resize(std::size_t(w) + 1);
  for (std::size_t x = 0; x <= std::size_t(w); ++x) {
    const int i0 = cols.i0[x], i1 = cols.i1[x];
    const float tu = cols.tu[x];
    const float top = row0[i0] + tu * (row0[i1] - row0[i0]);
    const float bottom = row1[i0] + tu * (row1[i1] - row1[i0]);
    out[x] = top + tv * (bottom - top) < threshold;
  }
}

}  // namespace

Image cull_prepass_simd(const Pass& r, const VaoSimdSets& sets, Counters& counters) {
  const int w = r.frame.width, h = r.frame.height;
  const int lw = (w + kVaoPpCullFactor - 1) / kVaoPpCullFactor;
  const int lh = (h + kVaoPpCullFactor - 1) / kVaoPpCullFactor;
  Image low(lw, lh, 1, 1.0f);
  VaoSimdCounts counts;
  counts.samples = kVaoPpCullSamples;
  parallel_for_rows(
      lh, r.threads,
      [&](int j0, int j1) {
        VaoSimdStats stats;
        for (int j = j0; j < j1; ++j) {
          const int y = std::min(j * kVaoPpCullFactor + kVaoPpCullFactor / 2, h - 1);
          vao_simd_span(r.frame, r.po, sets, counts, y, 0, lw, kVaoPpCullFactor,
                        kVaoPpCullFactor / 2, &low(0, j), 1, &stats);
        }
        counters.prepass_pixels += stats.pixels;
      },
      r.progress);
  return low;
}

Image occlusion_pass_simd(const Pass& r, const VaoSimdSets& sets, const Image& low,
                          Counters& counters) {
  const VaoPpSettings& s = r.s;
  const int w = r.frame.width, h = r.frame.height;
  const int channels = s.color_bleeding ? 4 : 1;
  Image work(w, h, channels, 1.0f);
  VaoPixelOptions full_po = r.po;
  full_po.bleeding_step = s.color_bleeding ? s.bleeding_sample_step : 0;
  VaoSimdCounts base;
  base.samples = s.samples;
  base.adaptive = s.adaptive_sampling;
  base.adaptive_min_diameter = s.adaptive_min_diameter;
  base.greedy = r.culling == VaoPpCulling::Greedy;
  base.careful = kVaoPpCarefulSamples;
  const CornerColumns columns(w, r.culling != VaoPpCulling::Off ? low.width() : 1);
  parallel_for_rows(
      h, r.threads,
      [&](int y0, int y1) {
        VaoSimdStats stats;
        std::vector<char> top, bottom;
        // The band's rows of §4.2's decisions (1 = culled), then its tiles.
        std::vector<float> culled(std::size_t(y1 - y0) * w, 0.0f);
        VaoSimdCounts counts = base;
        for (int y = y0; y < y1; ++y) {
          if (r.culling != VaoPpCulling::Off) {
            // Corner row y is row y − 1's bottom one.
            if (y == y0) occluded_corners(low, columns, y, w, s.cull_threshold, bottom);
            std::swap(top, bottom);
            occluded_corners(low, columns, y + 1, w, s.cull_threshold, bottom);
            for (int x = 0; x < w; ++x)
              culled[std::size_t(y - y0) * w + std::size_t(x)] =
                  (top[std::size_t(x)] | top[std::size_t(x) + 1] | bottom[std::size_t(x)] |
                   bottom[std::size_t(x) + 1])
                      ? 0.0f
                      : 1.0f;
          }
        }
        for (int x0 = 0; x0 < w; x0 += kSimdTileColumns)
          for (int y = y0; y < y1; ++y) {
            counts.culled = culled.data() + std::size_t(y - y0) * w;
            if (r.culling == VaoPpCulling::Off) counts.culled = nullptr;
            vao_simd_span(r.frame, full_po, sets, counts, y, x0, std::min(w, x0 + kSimdTileColumns),
                          1, 0, &work(0, y, 0), channels, &stats);
          }
        counters.pixels += stats.pixels;
        counters.culled += stats.culled;
        counters.samples += stats.samples;
      },
      r.progress, kSimdBandRows);
  return work;
}

}  // namespace aolab::vao_pp_detail
