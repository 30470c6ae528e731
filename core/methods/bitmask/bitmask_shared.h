// What the visibility bitmask's scalar code (bitmask.cpp) and its SIMD kernel (bitmask_simd.cpp)
// share: the SIMD kernel's entry. Private to core/methods/bitmask/ (docs/architecture.md, "Two
// kernels per method").
#pragma once

#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/horizon/slice.h"
#include "core/methods/bitmask/bitmask.h"

namespace aolab {

/// The SIMD kernel (bitmask_simd.cpp): the same algorithm as the scalar per-pixel code for
/// every setting, on consecutive pixels of a row at once. bitmask() runs it for Kernel::Simd.
Image bitmask_simd(const SliceFrame& f, const BitmaskSettings& s, int threads, Progress* progress);

}  // namespace aolab
