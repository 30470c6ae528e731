// The depth MIP chain (depth_mip.h): its layout, which pixel represents a block, the level a
// distance reads, and that every texel of every level holds its pixel's exact depth.
#include "core/base/depth_mip.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace aolab {
namespace {

Buffer<float> ramp(int w, int h) {
  Buffer<float> d(std::size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) d[std::size_t(y) * w + x] = float(y * 10000 + x);
  return d;
}

TEST(DepthMip, LayoutStopsWhereALevelWouldBeAllPartialBlocks) {
  const DepthMipLayout m = depth_mip_layout(203, 9, kMaxDepthMipLevel);
  EXPECT_EQ(m.levels, 3);  // 9 >> 4 == 0
  EXPECT_EQ(m.frame, 203 * 9);
  EXPECT_EQ(m.slot, 102 * 5);
  for (int l = 1; l <= m.levels; ++l) {
    EXPECT_EQ(m.width[l], (203 + (1 << l) - 1) >> l);
    EXPECT_EQ(m.height[l], (9 + (1 << l) - 1) >> l);
    EXPECT_EQ(m.offset[l], m.frame + (l - 1) * m.slot);
    EXPECT_LE(m.width[l] * m.height[l], m.slot);
  }
  EXPECT_EQ(depth_mip_layout(1, 1, kMaxDepthMipLevel).levels, 0);
  EXPECT_THROW(depth_mip_layout(8, 8, -1), std::invalid_argument);
  EXPECT_THROW(depth_mip_layout(8, 8, kMaxDepthMipLevel + 1), std::invalid_argument);
}

TEST(DepthMip, APixelNearTheBlockCentreRepresentsIt) {
  EXPECT_EQ(depth_mip_pixel(13, 0, 100), 13);
  EXPECT_EQ(depth_mip_pixel(13, 1, 100), 13);  // block 12..13 → 13
  EXPECT_EQ(depth_mip_pixel(12, 2, 100), 14);  // block 12..15 → 14
  EXPECT_EQ(depth_mip_pixel(97, 3, 100), 99);  // block 96..103 cut by the frame → its last
  for (int l = 0; l <= kMaxDepthMipLevel; ++l)
    for (int s = 0; s < 100; ++s) {
      const int p = depth_mip_pixel(s, l, 100);
      EXPECT_EQ(p >> l, s >> l);  // the same block
      EXPECT_LE(std::abs(p - s), (1 << l) >> 1 == 0 ? 0 : (1 << l) >> 1);
    }
}

TEST(DepthMip, LevelIsFloorLog2OfTheDistanceInUnitsOfQ) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  struct Case {
    float ratio;
    int levels, expected;
  };
  for (const Case& c : {Case{0.0f, 5, 0}, Case{0.99f, 5, 0}, Case{1.0f, 5, 0}, Case{1.99f, 5, 0},
                        Case{2.0f, 5, 1}, Case{31.9f, 5, 4}, Case{1e9f, 5, 5}, Case{1e9f, 2, 2},
                        Case{kInf, 3, 3}, Case{std::numeric_limits<float>::quiet_NaN(), 3, 0}})
    EXPECT_EQ(depth_mip_level(c.ratio, c.levels), c.expected) << c.ratio << ", " << c.levels;
}

TEST(DepthMip, EveryTexelHoldsItsPixelsDepthForAnyThreadCount) {
  for (const auto& [w, h] : {std::pair{203, 117}, std::pair{64, 64}, std::pair{7, 3}}) {
    Buffer<float> one = ramp(w, h), two = ramp(w, h);
    const DepthMipLayout m = depth_mip_layout(w, h, kMaxDepthMipLevel);
    build_depth_mip(one, m, 1);
    build_depth_mip(two, m, 2);
    EXPECT_EQ(one, two);
    const Buffer<float> frame = ramp(w, h);
    for (int l = 0; l <= m.levels; ++l)
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const int px = depth_mip_pixel(x, l, w), py = depth_mip_pixel(y, l, h);
          ASSERT_EQ(one[depth_mip_index(m, l, x, y)], frame[std::size_t(py) * w + px])
              << w << "x" << h << " level " << l << " at " << x << ", " << y;
        }
  }
}

}  // namespace
}  // namespace aolab
