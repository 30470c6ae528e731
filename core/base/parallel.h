// Row-parallel loops over images with a progress counter the caller can poll and a cancel flag
// (pbrt-v4's ProgressReporter habit). Work is split into fixed row bands handed out from an
// atomic counter; every pixel is computed by the same code whatever the band or thread, so
// results are identical for any thread count.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <stdexcept>

#include "core/base/image.h"

namespace aolab {

/// Shared between a computation and whoever watches it (the Python layer, the add-on).
struct Progress {
  std::atomic<std::int64_t> done{0};   ///< rows finished so far, over all passes
  std::atomic<std::int64_t> total{0};  ///< rows to do; set by the computation
  std::atomic<bool> cancel{false};     ///< set by the watcher; the computation then throws
};

/// Thrown out of a computation whose Progress::cancel was set.
struct Cancelled : std::runtime_error {
  Cancelled() : std::runtime_error("computation cancelled") {}
};

/// Number of worker threads for a `threads` setting: 0 means all cores; negative values
/// throw std::invalid_argument.
int resolve_threads(int threads);

/// Calls body(y_begin, y_end) for disjoint row bands covering [0, rows), on `threads` threads
/// (0 = all cores). Exceptions from a band are rethrown in the caller after all threads stop.
/// If `progress` is given, adds finished rows to progress->done and stops early with
/// Cancelled when progress->cancel is set.
void parallel_for_rows(int rows, int threads, const std::function<void(int, int)>& body,
                       Progress* progress = nullptr);

/// The per-pixel loop every method runs: a 1-channel `width` × `height` image whose pixel
/// (x, y) is pixel(scratch, x, y), rows in parallel bands as parallel_for_rows; each band gets
/// its own scratch from make_scratch() (working memory a pixel reuses). Adds `height` rows to
/// progress->total.
template <class MakeScratch, class Pixel>
Image image_from_pixels(int width, int height, int threads, Progress* progress,
                        MakeScratch make_scratch, Pixel pixel) {
  Image out(width, height, 1, 1.0f);
  if (progress) progress->total += height;
  parallel_for_rows(
      height, threads,
      [&](int y0, int y1) {
        auto scratch = make_scratch();
        for (int y = y0; y < y1; ++y)
          for (int x = 0; x < width; ++x) out(x, y) = pixel(scratch, x, y);
      },
      progress);
  return out;
}

/// The per-row loop of the SIMD kernels: a 1-channel `width` × `height` image whose row y is
/// filled by row(scratch, y, out_row) (out_row: `width` floats), rows in parallel bands as
/// parallel_for_rows, each band with its own scratch. Adds `height` rows to
/// progress->total.
template <class MakeScratch, class Row>
Image image_from_rows(int width, int height, int threads, Progress* progress,
                      MakeScratch make_scratch, Row row) {
  Image out(width, height, 1, 1.0f);
  if (progress) progress->total += height;
  parallel_for_rows(
      height, threads,
      [&](int y0, int y1) {
        auto scratch = make_scratch();
        for (int y = y0; y < y1; ++y) row(scratch, y, &out(0, y));
      },
      progress);
  return out;
}

}  // namespace aolab
