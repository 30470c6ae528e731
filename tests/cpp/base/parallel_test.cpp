#include "core/base/parallel.h"

#include <gtest/gtest.h>

#include <vector>

namespace aolab {
namespace {

TEST(ParallelForRows, CoversEveryRowOnce) {
  for (int threads : {1, 2, 5})
    for (int rows : {0, 1, 3, 4, 5, 101}) {
      std::vector<std::atomic<int>> hits(rows);
      parallel_for_rows(rows, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) hits[y]++;
      });
      for (int y = 0; y < rows; ++y) EXPECT_EQ(hits[y].load(), 1) << rows << " " << threads;
    }
}

TEST(ParallelForRows, ReportsProgressAndCancels) {
  Progress p;
  parallel_for_rows(
      40, 2, [](int, int) {}, &p);
  EXPECT_EQ(p.done.load(), 40);
  Progress c;
  c.cancel = true;
  EXPECT_THROW(parallel_for_rows(
                   40, 2, [](int, int) {}, &c),
               Cancelled);
}

TEST(ParallelForRows, RethrowsWorkerExceptions) {
  EXPECT_THROW(parallel_for_rows(40, 2,
                                 [](int y0, int) {
                                   if (y0 >= 20) throw std::runtime_error("boom");
                                 }),
               std::runtime_error);
}

TEST(ResolveThreads, ZeroIsAllCoresNegativeIsError) {
  EXPECT_GE(resolve_threads(0), 1);
  EXPECT_EQ(resolve_threads(3), 3);
  EXPECT_THROW(resolve_threads(-1), std::invalid_argument);
}

}  // namespace
}  // namespace aolab
