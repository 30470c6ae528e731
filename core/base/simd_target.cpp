#include "core/base/simd_target.h"

#include <hwy/highway.h>

#include <cstdint>

namespace aolab {

std::string simd_target_name() {
  // Highway numbers its targets so that a better one has a lower bit: the lowest bit of the
  // compiled ∩ supported set is the one HWY_DYNAMIC_DISPATCH chooses.
  const std::int64_t targets = hwy::SupportedTargets() & HWY_TARGETS;
  if (targets == 0) return hwy::TargetName(HWY_STATIC_TARGET);
  return hwy::TargetName(targets & -targets);
}

}  // namespace aolab
