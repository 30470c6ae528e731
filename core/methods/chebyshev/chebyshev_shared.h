// What Chebyshev AO's scalar code (chebyshev.cpp) and its SIMD kernel (chebyshev_simd.cpp)
// share: the frame as the passes read it and the plan of window sizes (levels), with the rows
// and columns each level's two passes cover, and the SIMD kernel's entry. Private to
// core/methods/chebyshev/ (docs/architecture.md, "Two kernels per method").
#pragma once

#include <cstdint>
#include <vector>

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/base/working_memory.h"
#include "core/methods/chebyshev/chebyshev.h"

namespace aolab::chebyshev_detail {

/// A frame's arrays: working arrays (working_memory.h), so that a frame reuses the last one's
/// memory; elements left default-initialised (no zero fill), so that the pages of a fresh array are
/// first touched, and faulted in, by the threads that write it rather than by one serial fill;
/// fresh arrays of 2 MiB or more in 2 MiB pages where Linux offers them for the asking (transparent
/// huge pages in "madvise" mode), since fresh memory costs a page fault per 4 KiB otherwise (a
/// quarter of the SIMD kernel's time at 1280×720 when measured, before the cache).
template <class T>
using FrameVector = UninitializedBuffer<T, WorkingMemoryPages::Huge>;

/// One window size: half-widths along x (the horizontal pass) and y (the vertical pass).
struct Level {
  int rh, rv;
};

/// The frame as the two passes read it: depth with background as 0 and a 0/1 weight, so the
/// passes can sum without branches (a background pixel adds 0 to every sum and to the count).
/// The vectors hold kFramePadding floats (ints) past the last pixel, zero (−1), so that a
/// SIMD kernel's last vector of a row may read past the image without leaving the array.
struct Frame {
  int w, h;
  FrameVector<float> depth, weight;
  FrameVector<int> level;  // per pixel: index into the level list, −1 = no window
};

/// Elements past the last pixel in every Frame vector: at least the widest vector of any
/// target (AVX-512: 16 floats).
constexpr int kFramePadding = 64;

/// The rows one level touches: the rows holding its receivers with their column span, and the
/// rows and columns the horizontal pass must cover (the union of the spans of the receiver
/// rows within their vertical half-width).
struct LevelRows {
  std::vector<int> receiver_rows, pass_rows;
  std::vector<int> span_lo, span_hi;  // per row: the receivers' columns (lo > hi: none)
  std::vector<int> need_lo, need_hi;  // per row: the columns the horizontal pass covers
};

/// Everything the passes need: the frame with every pixel's level, the levels (increasing
/// half-widths) and the rows of each; `total_rows` counts the rows of every level's two
/// passes (the progress total).
struct Plan {
  Frame frame;
  std::vector<Level> levels;
  std::vector<LevelRows> rows;
  std::int64_t total_rows = 0;
};

/// The plan of a validated G-buffer and settings (window sizes, §III; shrinking at
/// background); `threads` as RunOptions::threads, resolved.
Plan make_plan(const GBuffer& g, const ChebyshevSettings& s, int threads);

}  // namespace aolab::chebyshev_detail

namespace aolab {

/// The SIMD kernel (chebyshev_simd.cpp): the scalar passes on consecutive pixels of a row at
/// once, the same operations in the same order, so the same bits. Writes the moments (n, λ,
/// σ², 3 channels) of every pixel into `moments` if it is not null, else the visibility into
/// `ao` (1 channel, filled with 1 beforehand).
void chebyshev_simd(const chebyshev_detail::Plan& plan, const ChebyshevSettings& s, int threads,
                    Progress* progress, Image* moments, Image* ao);

}  // namespace aolab
