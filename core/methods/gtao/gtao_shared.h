// What GTAO's scalar code (gtao.cpp) and its SIMD kernel (gtao_simd.cpp) share: the SIMD kernel's
// entry. Private to core/methods/gtao/ (docs/architecture.md, "Two kernels per method").
#pragma once

#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/horizon/slice.h"
#include "core/methods/gtao/gtao.h"

namespace aolab {

/// The SIMD kernel (gtao_simd.cpp): the same algorithm as the scalar per-pixel code for every
/// setting, on consecutive pixels of a row at once. gtao() runs it for Kernel::Simd.
Image gtao_simd(const SliceFrame& f, const GtaoSettings& s, int threads, Progress* progress);

}  // namespace aolab
