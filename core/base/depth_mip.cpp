#include "core/base/depth_mip.h"

#include <stdexcept>
#include <string>

#include "core/base/check.h"
#include "core/base/parallel.h"

namespace aolab {

DepthMipLayout depth_mip_layout(int width, int height, int levels) {
  if (levels < 0 || levels > kMaxDepthMipLevel)
    throw_invalid("levels", "must be in [0, " + std::to_string(kMaxDepthMipLevel) + "]",
                  std::to_string(levels));
  DepthMipLayout m;
  m.width[0] = width, m.height[0] = height;
  const std::int64_t frame = std::int64_t(width) * height;
  const std::int64_t slot = std::int64_t((width + 1) >> 1) * ((height + 1) >> 1);
  CHECK_LT(frame + kMaxDepthMipLevel * slot, std::int64_t(1) << 31);  // int32 gather indices
  m.frame = std::int32_t(frame), m.slot = std::int32_t(slot);
  for (int l = 1; l <= levels; ++l) {
    if ((width >> l) < 1 || (height >> l) < 1) break;  // a level of partial blocks only
    m.width[l] = (width + (1 << l) - 1) >> l;
    m.height[l] = (height + (1 << l) - 1) >> l;
    m.offset[l] = std::int32_t(frame + (l - 1) * slot);
    m.levels = l;
  }
  return m;
}

void build_depth_mip(Buffer<float>& chain, const DepthMipLayout& m, int threads) {
  const int w = m.width[0], h = m.height[0];
  CHECK_GE(chain.size(), std::size_t(w) * std::size_t(h));
  chain.resize(std::size_t(m.frame) + std::size_t(m.levels) * std::size_t(m.slot));
  for (int l = 1; l <= m.levels; ++l) {
    float* level = chain.data() + m.offset[l];
    parallel_for_rows(m.height[l], threads, [&](int y0, int y1) {
      for (int j = y0; j < y1; ++j) {
        const std::size_t row = std::size_t(depth_mip_pixel(j << l, l, h)) * std::size_t(w);
        for (int i = 0; i < m.width[l]; ++i)
          level[std::size_t(j) * m.width[l] + i] = chain[row + depth_mip_pixel(i << l, l, w)];
      }
    });
  }
}

}  // namespace aolab
