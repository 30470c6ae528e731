// A process-wide cache of the large blocks the methods allocate per frame, and the allocator
// (Buffer<T>) that draws from it.
//
// Why: glibc's malloc serves a block above its mmap threshold (at most 32 MiB on 64-bit
// systems) with fresh pages from mmap and unmaps them on free, so every frame pays a page
// fault, and the kernel's zeroing, per 4 KiB it touches. At 3840×2160 a frame's working
// arrays (depth copy, prepared normals, output, pyramids, ...) are each above the threshold:
// about 40 000 faults a frame, which made the lightest methods take 14–17× as long as at
// 1280×720 for 9× the pixels, while the same arrays at 1280×720 stay in malloc's heap. The
// library runs inside Blender's process, so it must not change malloc's settings (mallopt,
// MALLOC_* variables); instead it keeps its own large blocks for the next frame.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <new>
#include <type_traits>
#include <vector>

namespace aolab {

/// Blocks below this go straight to operator new/delete: malloc keeps small blocks in its
/// heap already, and per-band scratch arrays inside parallel loops are of this kind.
constexpr std::size_t kWorkingMemoryMinBlock = std::size_t(1) << 20;

/// The default cap on the bytes the cache keeps idle. The largest frame, Chebyshev AO at
/// 3840×2160, needs ~385 MiB of arrays; 512 MiB keeps all of it between frames with room for
/// the output a caller still holds, and bounds what an idle Blender keeps to that.
constexpr std::size_t kDefaultWorkingMemoryLimit = std::size_t(512) << 20;

/// Every block (cached or not) starts on a multiple of this: at least a cache line and the
/// widest Highway vector (AVX-512: 64 bytes).
constexpr std::size_t kWorkingMemoryAlignment = 64;

/// What a fresh large block is backed by when the cache has none to reuse: Huge asks Linux for
/// 2 MiB pages (transparent huge pages in "madvise" mode), as Chebyshev AO's arrays were before
/// the cache; advice only, and a reused block keeps whatever backing it had.
enum class WorkingMemoryPages { Normal, Huge };

/// `bytes` aligned to kWorkingMemoryAlignment: from the cache (a block of at least `bytes` and
/// at most twice that, the smallest such, the most recently used of equals) or fresh. Throws
/// std::bad_alloc. Its contents are whatever the block held: the caller initialises them.
void* allocate_working_memory(std::size_t bytes,
                              WorkingMemoryPages pages = WorkingMemoryPages::Normal);

/// Gives back a block of allocate_working_memory with the same `bytes`: kept for reuse while
/// the cache stays within its limit (least recently used blocks leave first), else freed.
void free_working_memory(void* p, std::size_t bytes) noexcept;

struct WorkingMemoryStats {
  std::size_t cached_bytes = 0;  ///< idle in the cache, held for reuse
  std::size_t cached_blocks = 0;
  std::size_t in_use_bytes = 0;  ///< large blocks handed out and not yet given back
  std::size_t limit_bytes = 0;   ///< the cap on cached_bytes
};

/// A consistent snapshot (taken under the cache's lock).
WorkingMemoryStats working_memory_stats();
std::size_t working_memory_cached_bytes();
std::size_t working_memory_limit();

/// Caps the cached bytes at `limit_bytes` (0 = keep nothing: every large block is freed when
/// given back), evicting least recently used blocks down to it. Throws std::invalid_argument
/// naming limit_bytes if it is negative.
void set_working_memory_limit(std::int64_t limit_bytes);

/// Frees every cached block (the limit stays).
void release_working_memory();

/// A standard allocator drawing on the working-memory cache, fresh blocks backed by `kPages`.
/// Stateless and always equal, so containers move and swap their storage freely. Elements are
/// value-initialised as with std::allocator (a Buffer<float>(n) is n zeros): reused memory is
/// not zeroed by the kernel, so nothing may rely on fresh memory's zeros. With kDefaultInit a
/// container leaves new elements default-initialised instead (a resize of floats writes
/// nothing), for arrays whose every element read is proven written first: the pages of a
/// fresh array are then first touched by the threads that write them, not by a serial fill.
template <class T, WorkingMemoryPages kPages = WorkingMemoryPages::Normal,
          bool kDefaultInit = false>
struct CachingAllocator {
  using value_type = T;
  using propagate_on_container_move_assignment = std::true_type;
  using is_always_equal = std::true_type;
  template <class U>
  struct rebind {
    using other = CachingAllocator<U, kPages, kDefaultInit>;
  };

  CachingAllocator() = default;
  template <class U>
  CachingAllocator(const CachingAllocator<U, kPages, kDefaultInit>&) noexcept {}  // NOLINT

  T* allocate(std::size_t n) {
    static_assert(alignof(T) <= kWorkingMemoryAlignment);
    if (n > std::numeric_limits<std::size_t>::max() / sizeof(T)) throw std::bad_array_new_length();
    return static_cast<T*>(allocate_working_memory(n * sizeof(T), kPages));
  }
  void deallocate(T* p, std::size_t n) noexcept { free_working_memory(p, n * sizeof(T)); }

  // Without it (kDefaultInit false) std::allocator_traits value-initialises.
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) requires kDefaultInit {
    ::new (static_cast<void*>(p)) U;
  }

  template <class U>
  bool operator==(const CachingAllocator<U, kPages, kDefaultInit>&) const noexcept {
    return true;
  }
};

/// A frame-sized working array: a std::vector whose storage comes from the cache.
template <class T>
using Buffer = std::vector<T, CachingAllocator<T>>;

/// A working array whose new elements are left default-initialised (see CachingAllocator).
template <class T, WorkingMemoryPages kPages = WorkingMemoryPages::Normal>
using UninitializedBuffer = std::vector<T, CachingAllocator<T, kPages, true>>;

}  // namespace aolab
