// Row-parallel loops over images with a progress counter the caller can poll and a cancel flag
// (pbrt-v4's ProgressReporter habit). Work is split into fixed row bands handed out from an
// atomic counter; every pixel is computed by the same code whatever the band or thread, so
// results are identical for any thread count.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <stdexcept>

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

}  // namespace aolab
