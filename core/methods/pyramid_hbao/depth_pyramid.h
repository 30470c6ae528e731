// Depth pyramid of Pyramid HBAO (Astapov, Frolov, Galaktionov 2021, §3.3): level 0 is the
// linear depth buffer itself; level l + 1 has ⌈w_l / K⌉ × ⌈h_l / K⌉ texels, each the mean of
// the K×K texels of level l it covers. docs/methods/pyramid_hbao.md gives the details.
//
// - Depth is linear planar depth. The paper first converts a non-linear buffer value h to
//   linear depth z = n·f / (f − h·(f − n)) (§3.3, step 2); AO Lab's buffers already hold
//   linear planar depth, so there is nothing to convert.
// - Background (gbuffer.h) never enters a mean: a texel averages only its children that hold
//   geometry, and a texel with none is background (NaN).
// - Every texel also stores the centroid, in full-resolution pixel coordinates, of the pixel
//   centres its mean stands for (the mean of its children's centroids, with the same
//   weights as the depth). For a texel whose K^l × K^l footprint is all geometry inside the
//   image this is exactly the footprint's centre, K^l·(X + ½); where the image border or
//   background cuts the footprint it is the centre of what was averaged. Restoring the
//   position at the centroid keeps an averaged plane on or behind the plane (Jensen: planar
//   depth is a convex function of the pixel position), so averaging never lifts a surface
//   in front of itself.
// - Means are summed in double and rounded once per level: a constant depth stays exactly
//   constant at every level, and a level's relative rounding error is at most half a unit of
//   float32 more than its children's.
#pragma once

#include <span>
#include <vector>

#include "core/base/gbuffer.h"

namespace aolab {

/// The reduction factor K of the paper's choice (§3.3): "K was chosen to be 3" — the pyramid
/// is smaller and faster to build than with K = 2, for an insignificant quality difference.
constexpr int kDepthPyramidDefaultReduction = 3;

/// Longest image side accepted: K^l then fits an int for every level and K ≤ 64.
constexpr int kDepthPyramidMaxSide = 1 << 24;

/// One texel: mean linear depth (NaN = no geometry) and the centroid (x, y) of the pixel
/// centres behind it, in full-resolution pixel coordinates.
struct PyramidTexel {
  float depth;
  float x;
  float y;
};

/// One level of the pyramid.
struct DepthPyramidLevel {
  int width = 0;
  int height = 0;
  int scale = 1;                ///< K^l: full-resolution pixels per texel along each axis
  Buffer<PyramidTexel> texels;  ///< row-major, width × height; a working array

  const PyramidTexel& operator()(int x, int y) const {
    return texels[std::size_t(y) * std::size_t(width) + std::size_t(x)];
  }
};

class DepthPyramid {
 public:
  /// From the G-buffer's depth (background, by the G-buffer's rule, becomes NaN).
  /// `levels` counts level 0; 0 means all levels down to 1×1 (full_levels). Larger values
  /// are capped at full_levels: a 1×1 level has no coarser level. Throws
  /// std::invalid_argument for reduction outside [2, 64], negative levels, or an invalid
  /// G-buffer.
  DepthPyramid(const GBuffer& g, int reduction, int levels = 0, int threads = 0);

  /// From linear depth, row-major width × height, NaN marking background (any non-finite or
  /// non-positive value is treated as background too).
  DepthPyramid(std::span<const float> depth, int width, int height, int reduction, int levels = 0,
               int threads = 0);

  int levels() const { return int(levels_.size()); }
  int reduction() const { return reduction_; }
  const DepthPyramidLevel& level(int l) const { return levels_.at(std::size_t(l)); }

  /// Number of levels, level 0 included, until a level is 1×1: 1 + ⌈log_K max(w, h)⌉.
  static int full_levels(int width, int height, int reduction);

 private:
  void build(int levels, int threads);
  int reduction_;
  std::vector<DepthPyramidLevel> levels_;
};

}  // namespace aolab
