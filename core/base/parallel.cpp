#include "core/base/parallel.h"

#include <algorithm>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "core/base/check.h"

namespace aolab {

namespace {
// Rows per band: small enough to balance two to a few dozen threads on 720p, large enough
// that the atomic hand-out is negligible next to a row of AO.
constexpr int kRowsPerBand = 4;
}  // namespace

int resolve_threads(int threads) {
  if (threads < 0) throw_invalid("threads", "must be >= 0 (0 = all cores)", threads);
  if (threads == 0) return std::max(1u, std::thread::hardware_concurrency());
  return threads;
}

void parallel_for_rows(int rows, int threads, const std::function<void(int, int)>& body,
                       Progress* progress, int rows_per_band) {
  if (rows <= 0) return;
  const int band_rows = rows_per_band > 0 ? rows_per_band : kRowsPerBand;
  const int bands = (rows + band_rows - 1) / band_rows;
  const int workers = std::min(resolve_threads(threads), bands);
  std::atomic<int> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;

  auto work = [&] {
    for (;;) {
      if (failed.load(std::memory_order_relaxed)) return;
      if (progress && progress->cancel.load(std::memory_order_relaxed)) return;
      const int band = next.fetch_add(1, std::memory_order_relaxed);
      if (band >= bands) return;
      const int y0 = band * band_rows, y1 = std::min(rows, y0 + band_rows);
      try {
        body(y0, y1);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        failed = true;
        return;
      }
      if (progress) progress->done.fetch_add(y1 - y0, std::memory_order_relaxed);
    }
  };

  if (workers == 1) {
    work();
  } else {
    std::vector<std::thread> pool;
    pool.reserve(workers - 1);
    for (int t = 1; t < workers; ++t) pool.emplace_back(work);
    work();
    for (auto& th : pool) th.join();
  }
  if (error) std::rethrow_exception(error);
  if (progress && progress->cancel.load()) throw Cancelled();
}

}  // namespace aolab
