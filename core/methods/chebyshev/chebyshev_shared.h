// What Chebyshev AO's scalar code (chebyshev.cpp) and its SIMD kernel (chebyshev_simd.cpp)
// share: the frame as the passes read it and the plan of window sizes (levels), with the rows
// and columns each level's two passes cover, and the SIMD kernel's entry. Private to
// core/methods/chebyshev/ (docs/architecture.md, "Two kernels per method").
#pragma once

#include <cstdint>
#include <memory>
#include <new>
#include <utility>
#include <vector>

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/methods/chebyshev/chebyshev.h"

namespace aolab::chebyshev_detail {

/// Allocator of a frame's arrays: elements left default-initialised (no zero fill), so that
/// the pages of an array are first touched, and faulted in, by the threads that write it
/// rather than by one serial fill; and arrays of kHugePageBytes or more in 2 MiB pages where
/// Linux offers them for the asking (transparent huge pages in "madvise" mode), since a
/// frame's fresh memory costs a page fault per 4 KiB otherwise (a quarter of the SIMD
/// kernel's time at 1280×720 when measured).
void* allocate_frame_bytes(std::size_t bytes);
void free_frame_bytes(void* p, std::size_t bytes) noexcept;

template <class T>
struct DefaultInitAllocator {
  using value_type = T;
  DefaultInitAllocator() = default;
  template <class U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) { return static_cast<T*>(allocate_frame_bytes(n * sizeof(T))); }
  void deallocate(T* p, std::size_t n) noexcept { free_frame_bytes(p, n * sizeof(T)); }
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <class U>
  bool operator==(const DefaultInitAllocator<U>&) const noexcept {
    return true;
  }
};

/// A vector whose resize leaves new elements uninitialised.
template <class T>
using FrameVector = std::vector<T, DefaultInitAllocator<T>>;

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
