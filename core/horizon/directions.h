// The view-space directions a horizon-based method marches in (HBAO's directions, GTAO's and
// the visibility bitmask's slices and their opposites): a table built once per frame, turned
// per pixel.
#pragma once

#include <vector>

namespace aolab {

/// The N view-space directions θ_k = 2π (k + rotation) / N: a table of the unrotated
/// directions built once, rotated per pixel (one sincos per pixel instead of N).
class HorizonDirections {
 public:
  explicit HorizonDirections(int directions);
  int size() const { return int(base_cos_.size()); }
  /// cos/sin of the directions rotated by `rotation` (a fraction of the spacing, [0, 1)).
  void rotated(float rotation, float* cos_out, float* sin_out) const;
  /// The unrotated table: cos and sin of 2π k / N.
  const float* base_cos() const { return base_cos_.data(); }
  const float* base_sin() const { return base_sin_.data(); }

 private:
  std::vector<float> base_cos_, base_sin_;
};

}  // namespace aolab
