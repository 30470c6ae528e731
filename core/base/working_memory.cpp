#include "core/base/working_memory.h"

#include <algorithm>
#include <cstdlib>
#include <mutex>
#include <vector>

#include "core/base/check.h"

#ifdef __linux__
#include <pthread.h>
#include <sys/mman.h>
#endif

namespace aolab {

namespace {

// A large block starts with a header holding its size, so that a block handed to a smaller
// request (up to 2× larger) is cached and freed as what it is. One alignment unit keeps the
// caller's bytes aligned.
constexpr std::size_t kHeader = kWorkingMemoryAlignment;
static_assert(kHeader >= sizeof(std::size_t));
// Block sizes are whole pages (what the system maps anyway), so requests that differ by less
// than a page share blocks as equals.
constexpr std::size_t kPage = 4096;
constexpr std::size_t kHugePage = std::size_t(2) << 20;

std::size_t round_up(std::size_t n, std::size_t to) { return (n + to - 1) / to * to; }

std::size_t block_size(std::size_t bytes) { return round_up(bytes + kHeader, kPage); }

// A fresh block of `size` bytes or more; its real size is stored in its header.
std::byte* fresh_block(std::size_t size, WorkingMemoryPages pages) {
  std::size_t alignment = kWorkingMemoryAlignment;
#ifdef __linux__
  const bool huge = pages == WorkingMemoryPages::Huge && size >= kHugePage;
  if (huge) alignment = kHugePage, size = round_up(size, alignment);
#else
  (void)pages;
#endif
  auto* base = static_cast<std::byte*>(std::aligned_alloc(alignment, size));
  if (!base) throw std::bad_alloc();
#ifdef __linux__
  if (huge) madvise(base, size, MADV_HUGEPAGE);  // advice only: failure leaves 4 KiB pages
#endif
  *reinterpret_cast<std::size_t*>(base) = size;
  return base;
}

std::size_t size_of(const std::byte* base) { return *reinterpret_cast<const std::size_t*>(base); }

void before_fork();
void after_fork();

struct Block {
  std::byte* base;
  std::size_t size;
  std::uint64_t last_use;  // larger = more recently given back
};

class Cache {
 public:
  Cache() {
#ifdef __linux__
    // A process forked while another thread holds the lock (Python's multiprocessing can fork
    // while a computation runs) would inherit it locked for good: held across the fork, as
    // malloc does with its own locks, it is free on both sides.
    pthread_atfork(before_fork, after_fork, after_fork);
#endif
  }

  // The smallest cached block of [size, 2·size], the most recently used of equals; null if none.
  std::byte* take(std::size_t size) {
    const std::lock_guard<std::mutex> lock(mutex_);
    auto best = blocks_.end();
    for (auto it = blocks_.begin(); it != blocks_.end(); ++it)
      if (it->size >= size && it->size / 2 <= size &&
          (best == blocks_.end() || it->size < best->size ||
           (it->size == best->size && it->last_use > best->last_use)))
        best = it;
    if (best == blocks_.end()) return nullptr;
    std::byte* base = best->base;
    cached_ -= best->size;
    in_use_ += best->size;
    *best = blocks_.back();
    blocks_.pop_back();
    return base;
  }

  void count_fresh(std::size_t size) {
    const std::lock_guard<std::mutex> lock(mutex_);
    in_use_ += size;
  }

  // Keeps the block if it fits under the limit, then evicts down to the limit; frees what
  // leaves outside the lock.
  void give_back(std::byte* base) {
    const std::size_t size = size_of(base);
    std::vector<std::byte*> leaving;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      in_use_ -= size;
      if (size > limit_) {
        leaving.push_back(base);
      } else {
        blocks_.push_back({base, size, ++clock_});
        cached_ += size;
        evict_locked(leaving);
      }
    }
    for (std::byte* p : leaving) std::free(p);
  }

  void set_limit(std::size_t limit) {
    std::vector<std::byte*> leaving;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      limit_ = limit;
      evict_locked(leaving);
    }
    for (std::byte* p : leaving) std::free(p);
  }

  void release() {
    std::vector<Block> leaving;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      leaving.swap(blocks_);
      cached_ = 0;
    }
    for (const Block& b : leaving) std::free(b.base);
  }

  void lock_for_fork() { mutex_.lock(); }
  void unlock_after_fork() { mutex_.unlock(); }

  WorkingMemoryStats stats() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return {cached_, blocks_.size(), in_use_, limit_};
  }

 private:
  // Least recently used blocks out until the cache is within its limit.
  void evict_locked(std::vector<std::byte*>& leaving) {
    while (cached_ > limit_) {
      const auto oldest =
          std::min_element(blocks_.begin(), blocks_.end(),
                           [](const Block& a, const Block& b) { return a.last_use < b.last_use; });
      leaving.push_back(oldest->base);
      cached_ -= oldest->size;
      *oldest = blocks_.back();
      blocks_.pop_back();
    }
  }

  std::mutex mutex_;
  std::vector<Block> blocks_;  // unordered; last_use orders them
  std::size_t cached_ = 0, in_use_ = 0, limit_ = kDefaultWorkingMemoryLimit;
  std::uint64_t clock_ = 0;
};

// Never destroyed: a numpy array that owns an Image may be freed during interpreter shutdown,
// after static destructors would have run. What the cache holds at exit goes with the process.
Cache& cache() {
  static Cache* const c = new Cache;
  return *c;
}

void before_fork() { cache().lock_for_fork(); }
void after_fork() { cache().unlock_after_fork(); }

}  // namespace

void* allocate_working_memory(std::size_t bytes, WorkingMemoryPages pages) {
  if (bytes < kWorkingMemoryMinBlock)
    return ::operator new(bytes, std::align_val_t(kWorkingMemoryAlignment));
  const std::size_t size = block_size(bytes);
  std::byte* base = cache().take(size);
  if (!base) {
    base = fresh_block(size, pages);
    cache().count_fresh(size_of(base));
  }
  return base + kHeader;
}

void free_working_memory(void* p, std::size_t bytes) noexcept {
  if (!p) return;
  if (bytes < kWorkingMemoryMinBlock)
    return ::operator delete(p, std::align_val_t(kWorkingMemoryAlignment));
  cache().give_back(static_cast<std::byte*>(p) - kHeader);
}

WorkingMemoryStats working_memory_stats() { return cache().stats(); }

std::size_t working_memory_cached_bytes() { return working_memory_stats().cached_bytes; }

std::size_t working_memory_limit() { return working_memory_stats().limit_bytes; }

void set_working_memory_limit(std::int64_t limit_bytes) {
  if (limit_bytes < 0)
    throw_invalid("limit_bytes", "must be >= 0 bytes (0 = cache nothing)", limit_bytes);
  cache().set_limit(std::size_t(limit_bytes));
}

void release_working_memory() { cache().release(); }

}  // namespace aolab
