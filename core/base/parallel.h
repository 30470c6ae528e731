// Row-parallel loops over images with a progress counter the caller can poll and a cancel flag
// (pbrt-v4's ProgressReporter habit). Work is split into fixed row bands handed out from an
// atomic counter; every pixel is computed by the same code whatever the band or thread, so
// results are identical for any thread count.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

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
/// `rows_per_band` sets the band height (0: the default of 4 rows).
void parallel_for_rows(int rows, int threads, const std::function<void(int, int)>& body,
                       Progress* progress = nullptr, int rows_per_band = 0);

/// The scratch objects of one parallel loop: a band takes one (made by make() when none is
/// free) and gives it back when done, so that a loop makes as many as run at once rather than
/// one per band. Scratch arrays of a few hundred KiB made band after band are otherwise
/// allocated and handed back to the system by malloc each time, their pages faulted in again
/// (malloc keeps in its heap only what lies under thresholds it sets for itself). Only for
/// scratch whose leftovers from an earlier band never change what a band computes: which
/// band's leftovers a band finds depends on the threads' timing.
template <class T>
class ScratchPool {
 public:
  template <class Make>
  std::unique_ptr<T> take(Make make) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (!free_.empty()) {
        std::unique_ptr<T> scratch = std::move(free_.back());
        free_.pop_back();
        return scratch;
      }
    }
    return make();
  }
  void give(std::unique_ptr<T> scratch) {
    const std::lock_guard<std::mutex> lock(mutex_);
    free_.push_back(std::move(scratch));
  }

 private:
  std::mutex mutex_;
  std::vector<std::unique_ptr<T>> free_;
};

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

/// The loop of the SIMD kernels that read a neighbourhood of each pixel: bands of
/// `band_rows` rows in parallel; inside a band, column tiles of `tile_columns` pixels, all the
/// band's rows of one tile before the next tile, so that the neighbourhood a tile reads stays
/// in the core's own cache (row after row over the whole width, HBAO's ±R window of rows is
/// larger than a core's L2 at 1280×720). span(scratch, y, x0, x1, out_row) fills
/// out_row[x0, x1); `tile_columns` should be a multiple of the vector length, so that a row is
/// cut into vectors at the same places whatever the tile. Adds `height` rows to
/// progress->total.
template <class MakeScratch, class Span>
Image image_from_tiles(int width, int height, int threads, Progress* progress, int band_rows,
                       int tile_columns, MakeScratch make_scratch, Span span) {
  Image out(width, height, 1, 1.0f);
  if (progress) progress->total += height;
  parallel_for_rows(
      height, threads,
      [&](int y0, int y1) {
        auto scratch = make_scratch();
        for (int x0 = 0; x0 < width; x0 += tile_columns) {
          const int x1 = x0 + tile_columns < width ? x0 + tile_columns : width;
          for (int y = y0; y < y1; ++y) span(scratch, y, x0, x1, &out(0, y));
        }
      },
      progress, band_rows);
  return out;
}

}  // namespace aolab
