// The pool the regression gate runs callgrind trials on: results in job order whatever order they finish
// in, no more jobs at once than asked, and a job's exception thrown where its result is taken.
#include "harness/run/ordered_pool.hpp"

#include <atomic>
#include <chrono>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace growbench {
namespace {

TEST(OrderedPool, ResultsComeInJobOrderAndNoMoreRunAtOnceThanItsWidth) {
  std::atomic<int> running{0}, most{0};
  OrderedPool<std::size_t> pool(12, 3, [&](std::size_t i) {
    const int now = ++running;
    for (int m = most.load(); now > m && !most.compare_exchange_weak(m, now);) {
    }
    // The first three wait for each other (up to a few seconds on a loaded machine): they must overlap.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (i < 3 && running.load() < 3 && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
    // Early jobs take longest, so later ones finish first.
    std::this_thread::sleep_for(std::chrono::milliseconds(5 * static_cast<int>(12 - i)));
    --running;
    return i * i;
  });
  for (std::size_t i = 0; i < 12; ++i) EXPECT_EQ(pool.take(i), i * i);
  EXPECT_EQ(most.load(), 3);
}

TEST(OrderedPool, AJobsErrorIsThrownWhereItsResultIsTakenAndTheOthersStillArrive) {
  OrderedPool<std::string> pool(4, 2, [](std::size_t i) {
    if (i == 1) throw std::runtime_error("job 1 failed");
    return std::to_string(i);
  });
  EXPECT_EQ(pool.take(0), "0");
  try {
    pool.take(1);
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "job 1 failed");
  }
  EXPECT_EQ(pool.take(2), "2");
  EXPECT_EQ(pool.take(3), "3");
}

TEST(OrderedPool, LeftEarlyItStartsNoFurtherJobs) {
  std::atomic<int> started{0};
  {
    OrderedPool<int> pool(100, 2, [&](std::size_t) {
      ++started;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      return 0;
    });
    pool.take(0);
  }
  EXPECT_LT(started.load(), 10);
}

}  // namespace
}  // namespace growbench
