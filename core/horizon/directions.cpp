#include "core/horizon/directions.h"

#include <cmath>
#include <numbers>

namespace aolab {

HorizonDirections::HorizonDirections(int directions)
    : base_cos_(directions), base_sin_(directions) {
  const double spacing = 2.0 * std::numbers::pi / directions;
  for (int k = 0; k < directions; ++k) {
    base_cos_[k] = float(std::cos(spacing * k));
    base_sin_[k] = float(std::sin(spacing * k));
  }
}

void HorizonDirections::rotated(float rotation, float* cos_out, float* sin_out) const {
  const float phi = float(2.0 * std::numbers::pi / size() * rotation);
  const float cp = std::cos(phi), sp = std::sin(phi);
  for (int k = 0; k < size(); ++k) {
    cos_out[k] = base_cos_[k] * cp - base_sin_[k] * sp;
    sin_out[k] = base_sin_[k] * cp + base_cos_[k] * sp;
  }
}

}  // namespace aolab
