// run/ordered_work: the threaded pipeline's building blocks keep the order of the work and hand
// failures back to the caller, threaded or not.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "run/ordered_work.hpp"

namespace gvio::run {
namespace {

class OrderedWorkTest : public ::testing::TestWithParam<bool> {};

TEST_P(OrderedWorkTest, WorkerRunsTasksInSubmissionOrder) {
  std::vector<int> done;
  {
    OrderedWorker worker(GetParam(), 2);
    for (int i = 0; i < 200; ++i) worker.submit([&done, i] { done.push_back(i); });
    worker.drain();
    ASSERT_EQ(done.size(), 200U);
    for (int i = 0; i < 200; ++i) EXPECT_EQ(done[static_cast<std::size_t>(i)], i);
    worker.submit([&done] { done.push_back(-1); });
    worker.drain();
  }
  EXPECT_EQ(done.back(), -1);
}

TEST_P(OrderedWorkTest, WorkerFailureReachesTheCallerAndStopsLaterTasks) {
  OrderedWorker worker(GetParam(), 1);
  int ran = 0;
  const auto submitAll = [&] {
    worker.submit([&ran] { ++ran; });
    worker.submit([] { throw std::runtime_error("keyframe 2 failed"); });
    for (int i = 0; i < 5; ++i) worker.submit([&ran] { ++ran; });
    worker.drain();
  };
  try {
    submitAll();
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "keyframe 2 failed");
  }
  EXPECT_EQ(ran, 1);  // nothing after the failed task ran
}

TEST_P(OrderedWorkTest, PrefetcherYieldsItemsInOrderThenEnds) {
  Prefetcher<int> items(GetParam(), 3, [](std::size_t i) -> std::optional<int> {
    if (i >= 100) return std::nullopt;
    return static_cast<int>(i * i);
  });
  for (int i = 0; i < 100; ++i) {
    const std::optional<int> item = items.next();
    ASSERT_TRUE(item.has_value());
    EXPECT_EQ(*item, i * i);
  }
  EXPECT_FALSE(items.next().has_value());
  EXPECT_FALSE(items.next().has_value());
}

TEST_P(OrderedWorkTest, PrefetcherFailureComesAfterTheItemsBeforeIt) {
  Prefetcher<int> items(GetParam(), 2, [](std::size_t i) -> std::optional<int> {
    if (i == 5) throw std::runtime_error("frame 5: bad image size");
    return static_cast<int>(i);
  });
  for (int i = 0; i < 5; ++i) EXPECT_EQ(items.next(), i);
  EXPECT_THROW(items.next(), std::runtime_error);
}

TEST_P(OrderedWorkTest, AnAbandonedPrefetcherStopsCleanly) {
  Prefetcher<int> items(GetParam(), 2,
                        [](std::size_t i) -> std::optional<int> { return static_cast<int>(i); });
  EXPECT_EQ(items.next(), 0);
}  // the destructor stops the producer, which is waiting for room in the queue

INSTANTIATE_TEST_SUITE_P(ThreadedAndInline, OrderedWorkTest, ::testing::Bool());

}  // namespace
}  // namespace gvio::run
