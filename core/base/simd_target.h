// Which instruction set the SIMD kernels run on: Highway compiles every kernel for several
// targets and picks the best one the processor supports at run time.
#pragma once

#include <string>

namespace aolab {

/// The name of the best target that is both compiled in and supported here, as Highway names
/// it ("AVX3" for AVX-512, "AVX2", "SSE4", "NEON", ...): what the benchmarks ran on.
std::string simd_target_name();

}  // namespace aolab
