#include "core/base/camera.h"

#include <cmath>

#include "core/base/check.h"

namespace aolab {

void CameraIntrinsics::validate() const {
  if (!std::isfinite(fx) || fx <= 0)
    throw_invalid("fx", "must be a finite focal length > 0 px", fx);
  if (!std::isfinite(fy) || fy <= 0)
    throw_invalid("fy", "must be a finite focal length > 0 px", fy);
  if (!std::isfinite(cx)) throw_invalid("cx", "must be finite", cx);
  if (!std::isfinite(cy)) throw_invalid("cy", "must be finite", cy);
}

}  // namespace aolab
