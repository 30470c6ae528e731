// A chain of point-sampled depth levels for a kernel's far samples: level l holds one pixel
// of each 2^l × 2^l block, the pixel nearest the block's centre, with its exact depth. A far
// sample snaps to its block's pixel and reads it from the level, whose texels are 4^l times
// closer together in memory than the frame's: the samples of a large radius then stay in
// the cache (XeGTAO and Scalable AO read a depth MIP chain for the same reason; McGuire et
// al. 2012, "Scalable Ambient Obscurance", §3). Unlike their chains, a level here stores
// a real pixel's depth, and the sample takes that pixel's position, so it is an exact point
// of the surface: an open plane stays unoccluded. Only where a far sample lands moves, by
// at most 2^(l-1) pixels.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/base/working_memory.h"

namespace aolab {

/// The coarsest level: blocks of 32 × 32 pixels.
constexpr int kMaxDepthMipLevel = 5;

/// Where level l lives in the chain's buffer: level 0 is the frame (width × height floats,
/// row-major) and starts it; levels 1..levels follow, each in a slot the size of level 1, so
/// that a level's offset is arithmetic (frame + (l − 1)·slot): a SIMD kernel computes it per
/// lane instead of gathering it from a table, which would cost as much as the depth's own
/// gather. The slots waste a quarter of the frame (levels 2..5 fill a third of theirs).
struct DepthMipLayout {
  int levels = 0;
  std::int32_t frame = 0;  ///< width × height: where level 1 starts
  std::int32_t slot = 0;   ///< the floats of level 1, the stride between levels
  std::array<std::int32_t, kMaxDepthMipLevel + 1> offset{}, width{}, height{};
};

/// The pixel that represents coordinate `s` (0 ≤ s < size) at level l: the one nearest the
/// centre of its 2^l block, inside the frame.
inline int depth_mip_pixel(int s, int level, int size) {
  return std::min(((s >> level) << level) + ((1 << level) >> 1), size - 1);
}

/// The level a sample `distance_over_q` = r/q times the chain's start distance q from its
/// receiver reads: floor(log2(r/q)), from 0 up to `levels` (below q: level 0, the frame).
inline int depth_mip_level(float distance_over_q, int levels) {
  // The exponent of a positive float is floor(log2) for normal numbers; the SIMD kernels take
  // the same bits, so both pick the same level.
  if (!(distance_over_q >= 1.0f)) return 0;
  std::uint32_t bits;
  static_assert(sizeof(bits) == sizeof(distance_over_q));
  std::copy_n(reinterpret_cast<const unsigned char*>(&distance_over_q), sizeof(bits),
              reinterpret_cast<unsigned char*>(&bits));
  return std::min(int(bits >> 23) - 127, levels);
}

/// The index in the chain of level l's texel for frame pixel (x, y).
inline std::size_t depth_mip_index(const DepthMipLayout& m, int level, int x, int y) {
  return std::size_t(m.offset[level]) + std::size_t(y >> level) * std::size_t(m.width[level]) +
         std::size_t(x >> level);
}

/// The layout of a chain of `levels` (0..kMaxDepthMipLevel) levels over a width × height
/// frame; levels smaller than one texel are not made (the chain stops there).
DepthMipLayout depth_mip_layout(int width, int height, int levels);

/// Appends levels 1..layout.levels to `chain`, whose first width × height floats are level 0
/// (the frame's depth), resizing it; rows in parallel on `threads`.
void build_depth_mip(Buffer<float>& chain, const DepthMipLayout& layout, int threads);

}  // namespace aolab
