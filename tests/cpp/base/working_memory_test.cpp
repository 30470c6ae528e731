#include "core/base/working_memory.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

constexpr std::size_t kMiB = std::size_t(1) << 20;

// Every test starts from an empty cache with the default limit, and leaves it so.
class WorkingMemory : public ::testing::Test {
 protected:
  void SetUp() override { reset(); }
  void TearDown() override { reset(); }
  static void reset() {
    set_working_memory_limit(std::int64_t(kDefaultWorkingMemoryLimit));
    release_working_memory();
  }
  static WorkingMemoryStats stats() { return working_memory_stats(); }
};

TEST_F(WorkingMemory, ABlockGivenBackServesTheNextRequestOfItsSize) {
  void* a = allocate_working_memory(3 * kMiB);
  const std::size_t in_use = stats().in_use_bytes;
  EXPECT_GE(in_use, 3 * kMiB);
  free_working_memory(a, 3 * kMiB);
  EXPECT_EQ(stats().cached_blocks, 1u);
  EXPECT_GE(stats().cached_bytes, 3 * kMiB);
  EXPECT_EQ(stats().in_use_bytes, in_use - stats().cached_bytes);
  void* b = allocate_working_memory(3 * kMiB);
  EXPECT_EQ(b, a);
  EXPECT_EQ(stats().cached_bytes, 0u);
  EXPECT_EQ(stats().in_use_bytes, in_use);
  free_working_memory(b, 3 * kMiB);
}

TEST_F(WorkingMemory, ABlockServesRequestsDownToHalfItsSizeTheSmallestFitFirst) {
  void* big = allocate_working_memory(4 * kMiB);
  void* mid = allocate_working_memory(3 * kMiB);
  free_working_memory(big, 4 * kMiB);
  free_working_memory(mid, 3 * kMiB);
  void* p = allocate_working_memory(2 * kMiB + 1);  // both fit: the smaller one
  EXPECT_EQ(p, mid);
  void* q = allocate_working_memory(2 * kMiB + 1);  // 4 MiB is under twice the request
  EXPECT_EQ(q, big);
  free_working_memory(p, 2 * kMiB + 1);
  free_working_memory(q, 2 * kMiB + 1);
  // A request under half of every cached block gets a fresh one, and the cache keeps its two.
  void* r = allocate_working_memory(kMiB + kMiB / 4);
  EXPECT_NE(r, mid);
  EXPECT_NE(r, big);
  EXPECT_EQ(stats().cached_blocks, 2u);
  free_working_memory(r, kMiB + kMiB / 4);
}

TEST_F(WorkingMemory, TheLimitHoldsAndTheLeastRecentlyUsedBlockLeavesFirst) {
  // Room for two blocks of 3 MiB (each a little more with its header), not three.
  set_working_memory_limit(std::int64_t(7 * kMiB));
  void* a = allocate_working_memory(3 * kMiB);
  void* b = allocate_working_memory(3 * kMiB);
  void* c = allocate_working_memory(3 * kMiB);
  for (void* p : {a, b, c}) {
    free_working_memory(p, 3 * kMiB);
    EXPECT_LE(stats().cached_bytes, 7 * kMiB);
  }
  EXPECT_EQ(stats().cached_blocks, 2u);
  // a, given back first, left; the most recently given back comes first.
  EXPECT_EQ(allocate_working_memory(3 * kMiB), c);
  EXPECT_EQ(allocate_working_memory(3 * kMiB), b);
  EXPECT_EQ(stats().cached_blocks, 0u);
  free_working_memory(b, 3 * kMiB);
  free_working_memory(c, 3 * kMiB);

  // Lowering the limit evicts down to it, the least recently used first.
  const std::size_t one = stats().cached_bytes / 2;
  set_working_memory_limit(std::int64_t(one));
  EXPECT_EQ(stats().cached_blocks, 1u);
  EXPECT_EQ(stats().cached_bytes, one);
  EXPECT_EQ(allocate_working_memory(3 * kMiB), c);
  free_working_memory(c, 3 * kMiB);
}

TEST_F(WorkingMemory, ALimitOfZeroCachesNothingAndFreesWhatWasCached) {
  void* a = allocate_working_memory(2 * kMiB);
  void* b = allocate_working_memory(2 * kMiB);
  free_working_memory(a, 2 * kMiB);
  EXPECT_EQ(stats().cached_blocks, 1u);
  set_working_memory_limit(0);
  EXPECT_EQ(working_memory_limit(), 0u);
  EXPECT_EQ(working_memory_cached_bytes(), 0u);
  free_working_memory(b, 2 * kMiB);
  EXPECT_EQ(working_memory_cached_bytes(), 0u);
  EXPECT_EQ(stats().cached_blocks, 0u);
}

TEST_F(WorkingMemory, ABlockLargerThanTheLimitIsFreed) {
  set_working_memory_limit(std::int64_t(2 * kMiB));
  void* a = allocate_working_memory(3 * kMiB);
  free_working_memory(a, 3 * kMiB);
  EXPECT_EQ(stats().cached_bytes, 0u);
}

TEST_F(WorkingMemory, ReleaseFreesEveryCachedBlockAndKeepsTheLimit) {
  set_working_memory_limit(std::int64_t(64 * kMiB));
  std::vector<void*> blocks;
  for (int i = 1; i <= 4; ++i) blocks.push_back(allocate_working_memory(std::size_t(i) * kMiB));
  for (int i = 1; i <= 4; ++i)
    free_working_memory(blocks[std::size_t(i - 1)], std::size_t(i) * kMiB);
  EXPECT_EQ(stats().cached_blocks, 4u);
  release_working_memory();
  EXPECT_EQ(stats().cached_bytes, 0u);
  EXPECT_EQ(stats().cached_blocks, 0u);
  EXPECT_EQ(working_memory_limit(), 64 * kMiB);
}

TEST_F(WorkingMemory, SmallBlocksBypassTheCache) {
  const std::size_t in_use = stats().in_use_bytes;
  for (std::size_t bytes : {std::size_t(1), std::size_t(4096), kWorkingMemoryMinBlock - 1}) {
    void* p = allocate_working_memory(bytes);
    EXPECT_EQ(stats().in_use_bytes, in_use) << bytes;
    free_working_memory(p, bytes);
    EXPECT_EQ(stats().cached_bytes, 0u) << bytes;
  }
  Buffer<float> small(1000);
  small.clear();
  small.shrink_to_fit();
  EXPECT_EQ(stats().cached_bytes, 0u);
}

TEST_F(WorkingMemory, EveryBlockIsAlignedForTheWidestVector) {
  EXPECT_GE(kWorkingMemoryAlignment, 64u);
  for (std::size_t bytes : {std::size_t(4), std::size_t(100), std::size_t(65536),
                            kWorkingMemoryMinBlock, 3 * kMiB + 12345})
    for (WorkingMemoryPages pages : {WorkingMemoryPages::Normal, WorkingMemoryPages::Huge}) {
      void* p = allocate_working_memory(bytes, pages);
      EXPECT_EQ(reinterpret_cast<std::uintptr_t>(p) % kWorkingMemoryAlignment, 0u) << bytes;
      std::memset(p, 0xab, bytes);  // all of it is ours
      free_working_memory(p, bytes);
    }
  const Buffer<float> floats(1000003);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(floats.data()) % 64, 0u);
}

TEST_F(WorkingMemory, ABufferIsZeroedOnReuseAsAStdVectorIs) {
  const std::size_t n = 2 * kMiB / sizeof(float);
  const float* first = nullptr;
  {
    Buffer<float> a(n);
    std::fill(a.begin(), a.end(), 7.0f);
    first = a.data();
  }
  const Buffer<float> b(n);
  EXPECT_EQ(b.data(), first);  // the same memory, reused
  EXPECT_TRUE(std::all_of(b.begin(), b.end(), [](float v) { return v == 0.0f; }));
  // A default-initialising buffer leaves reused memory as it was: only for arrays whose every
  // element is written before it is read.
  UninitializedBuffer<float> c(n);
  c[0] = 1.0f;
  EXPECT_EQ(c.size(), n);
}

TEST_F(WorkingMemory, BuffersMoveAndSwapTheirStorage) {
  Buffer<float> a(kMiB);
  const float* data = a.data();
  Buffer<float> b = std::move(a);
  EXPECT_EQ(b.data(), data);
  Buffer<float> c;
  c = std::move(b);
  EXPECT_EQ(c.data(), data);
  Buffer<float> d(10);
  std::swap(c, d);
  EXPECT_EQ(d.data(), data);
}

TEST_F(WorkingMemory, ConcurrentUseHandsEveryBlockToOneHolderAndAccountsForAll) {
  // A limit the threads exceed, so that they evict as well as reuse.
  set_working_memory_limit(std::int64_t(12 * kMiB));
  const std::size_t in_use = stats().in_use_bytes;
  constexpr int kThreads = 4, kRounds = 1000;
  const std::size_t sizes[] = {kMiB, 3 * kMiB / 2, 2 * kMiB, 3 * kMiB, 5 * kMiB, 64 * 1024};
  std::vector<std::thread> threads;
  std::vector<int> failures(kThreads, 0);
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      std::mt19937 random{std::uint32_t(t)};
      struct Held {
        std::uint32_t* p;
        std::size_t bytes;
        std::uint32_t tag;
      };
      std::vector<Held> held;
      for (int round = 0; round < kRounds; ++round) {
        const std::size_t bytes = sizes[random() % std::size(sizes)];
        auto* p = static_cast<std::uint32_t*>(allocate_working_memory(bytes));
        const std::uint32_t tag = std::uint32_t(t * kRounds + round);
        const std::size_t words = bytes / sizeof(std::uint32_t);
        p[0] = p[words / 2] = p[words - 1] = tag;
        held.push_back({p, bytes, tag});
        if (held.size() > 3 || random() % 2) {  // give one back, checking nobody else wrote it
          const std::size_t i = random() % held.size();
          const auto [q, n, mine] = held[i];
          const std::size_t w = n / sizeof(std::uint32_t);
          if (q[0] != mine || q[w / 2] != mine || q[w - 1] != mine) ++failures[std::size_t(t)];
          free_working_memory(q, n);
          held.erase(held.begin() + std::ptrdiff_t(i));
        }
        if (stats().cached_bytes > 12 * kMiB) ++failures[std::size_t(t)];
      }
      for (const Held& h : held) free_working_memory(h.p, h.bytes);
    });
  for (std::thread& th : threads) th.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(failures[std::size_t(t)], 0) << "thread " << t;
  const WorkingMemoryStats end = stats();
  EXPECT_EQ(end.in_use_bytes, in_use);
  EXPECT_LE(end.cached_bytes, 12 * kMiB);
  EXPECT_GT(end.cached_blocks, 0u);
  release_working_memory();
  EXPECT_EQ(stats().cached_bytes, 0u);
}

TEST_F(WorkingMemory, ANegativeLimitIsRefusedNamingItAndTheValue) {
  const std::string message =
      testing::invalid_argument_message([] { set_working_memory_limit(-1); });
  EXPECT_NE(message.find("limit_bytes"), std::string::npos) << message;
  EXPECT_NE(message.find("got -1"), std::string::npos) << message;
  EXPECT_EQ(working_memory_limit(), kDefaultWorkingMemoryLimit);  // unchanged
  EXPECT_THROW(set_working_memory_limit(INT64_MIN), std::invalid_argument);
}

}  // namespace
}  // namespace aolab
