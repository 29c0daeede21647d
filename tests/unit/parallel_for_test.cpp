#include "odometry/parallel_for.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <stdexcept>
#include <thread>
#include <vector>

namespace gvio {
namespace {

TEST(ParallelFor, EveryIndexOnceWhateverTheThreads) {
  for (const unsigned threads : {1U, 2U, 3U, 8U, 64U}) {
    std::vector<int> runs(1000, 0);
    parallelFor(runs.size(), threads, [&](std::size_t i) { runs[i] += static_cast<int>(i) + 1; });
    for (std::size_t i = 0; i < runs.size(); ++i) {
      ASSERT_EQ(runs[i], static_cast<int>(i) + 1) << "threads " << threads << " index " << i;
    }
  }
}

TEST(ParallelFor, NothingToDoStartsNoWork) {
  int calls = 0;
  parallelFor(0, 4, [&](std::size_t) { ++calls; });
  EXPECT_EQ(calls, 0);
}

TEST(ParallelFor, TheFirstExceptionStopsTheLoopAndIsRethrown) {
  for (const unsigned threads : {1U, 4U}) {
    std::atomic<int> calls{0};
    EXPECT_THROW(parallelFor(100000, threads,
                             [&](std::size_t i) {
                               ++calls;
                               if (i == 10) throw std::runtime_error("item 10");
                               // Items that take time, as real ones do: with empty items the
                               // other threads ran thousands while the thrower was unwinding on
                               // a loaded machine (seen under ctest -j2 beside a benchmark).
                               std::this_thread::sleep_for(std::chrono::milliseconds(1));
                             }),
                 std::runtime_error);
    // Items already handed out may finish; no thread keeps taking new ones (without the stop
    // the 100000 items would take 25 s or more).
    EXPECT_LT(calls.load(), 1000) << "threads " << threads;
  }
}

TEST(ParallelFor, ThreadCountHonoursRequestAndCap) {
  EXPECT_EQ(threadCount(3, 8), 3U);
  EXPECT_EQ(threadCount(20, 8), 8U);
  EXPECT_GE(threadCount(0, 8), 1U);
  EXPECT_LE(threadCount(0, 8), 8U);
  EXPECT_EQ(threadCount(-1, 1), 1U);
}

}  // namespace
}  // namespace gvio
