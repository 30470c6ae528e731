// What HBAO's scalar code (hbao.cpp) and its SIMD kernel (hbao_simd.cpp) share: the SIMD
// kernel's entry. Private to core/methods/hbao/ (docs/architecture.md, "Two kernels per
// method").
#pragma once

#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/methods/hbao/hbao.h"

namespace aolab {

/// The SIMD kernel (hbao_simd.cpp): the same algorithm as the scalar per-pixel code for every
/// setting, on consecutive pixels of a row at once. hbao() runs it for Kernel::Simd.
Image hbao_simd(const HorizonFrame& f, const HbaoSettings& s, int threads, Progress* progress);

}  // namespace aolab
