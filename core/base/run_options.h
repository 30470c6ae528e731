// How a computation runs (threads, progress, which kernel), not what it computes: what every
// method (core/methods/) and the ray-traced reference (core/raytracing/) take beside their
// settings.
#pragma once

#include "core/base/parallel.h"

namespace aolab {

/// Which implementation of a method runs. Both compute the same algorithm with the same
/// settings; they differ in how (docs/benchmarks.md).
enum class Kernel : int {
  /// The vectorised kernel (Highway, several pixels per instruction, the best instruction set
  /// chosen at run time) where the method has one, else its scalar code. The default.
  Simd = 0,
  /// The straightforward per-pixel float code: the oracle each SIMD kernel is tested
  /// against, within a tolerance stated in its test, and the benchmarks' baseline.
  Scalar = 1,
};

/// How a computation runs (not what it computes).
struct RunOptions {
  int threads = 0;               ///< worker threads, 0 = all cores
  Progress* progress = nullptr;  ///< optional progress counter and cancel flag
  Kernel kernel = Kernel::Simd;  ///< the implementation; the result differs by rounding only
};

}  // namespace aolab
