// WorkerPool (host/common/worker_pool.h): every index runs once per run, on the pool's
// threads and the caller's, run after run; the lowest index's exception reaches the caller
// after the others have finished; one thread runs everything on the caller.
#include "host/common/worker_pool.h"

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace sigmafem {
namespace {

TEST(WorkerPool, RunsEveryIndexOnceRunAfterRun) {
  WorkerPool pool(3);
  EXPECT_EQ(pool.threads(), 3);
  for (int run = 0; run < 200; ++run) {
    const int count = run % 7;   // fewer, as many and more indices than threads, and none
    std::vector<std::atomic<int>> calls(static_cast<std::size_t>(count));
    pool.run(count, [&](int i) { ++calls[static_cast<std::size_t>(i)]; });
    for (int i = 0; i < count; ++i) ASSERT_EQ(calls[static_cast<std::size_t>(i)].load(), 1) << "run " << run << ", index " << i;
  }
}

TEST(WorkerPool, UsesItsThreadsAndTheCallers) {
  WorkerPool pool(2);
  std::set<std::thread::id> seen;
  std::mutex seen_mutex;
  // Each index waits until two threads have arrived, so both must take part.
  std::atomic<int> arrived{0};
  pool.run(2, [&](int) {
    {
      std::lock_guard<std::mutex> lock(seen_mutex);
      seen.insert(std::this_thread::get_id());
    }
    ++arrived;
    while (arrived.load() < 2) std::this_thread::yield();
  });
  EXPECT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen.count(std::this_thread::get_id()), 1u) << "the caller works too";
}

TEST(WorkerPool, RethrowsTheLowestIndexsExceptionAfterTheOthersFinish) {
  WorkerPool pool(2);
  std::atomic<int> finished{0};
  try {
    pool.run(6, [&](int i) {
      if (i == 1 || i == 4) throw std::runtime_error("index " + std::to_string(i));
      ++finished;
    });
    FAIL() << "the exception did not reach the caller";
  } catch (const std::runtime_error& error) {
    EXPECT_STREQ(error.what(), "index 1");
  }
  EXPECT_EQ(finished.load(), 4) << "the other indices ran";
  std::atomic<int> after{0};
  pool.run(3, [&](int) { ++after; });
  EXPECT_EQ(after.load(), 3) << "the pool still works after an exception";
}

TEST(WorkerPool, OneThreadRunsEverythingOnTheCaller) {
  WorkerPool pool(1);
  const std::thread::id caller = std::this_thread::get_id();
  std::vector<int> order;
  pool.run(4, [&](int i) {
    EXPECT_EQ(std::this_thread::get_id(), caller);
    order.push_back(i);
  });
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 3}));
}

}  // namespace
}  // namespace sigmafem
