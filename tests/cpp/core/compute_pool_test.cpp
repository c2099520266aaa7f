#include "core/compute_pool.h"

#include <atomic>
#include <set>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace graspsim {
namespace {

// Every item is done exactly once, by at most `width` distinct threads, the caller among them.
TEST(ComputePoolTest, RunDoesEveryItemOnceOnAtMostWidthThreads) {
  ComputePool pool(3);
  ASSERT_EQ(pool.threads(), 3u);
  for (size_t width : {0u, 1u, 2u, 3u, 8u}) {
    std::vector<std::atomic<int>> hits(5000);
    std::atomic<size_t> next{0};
    std::mutex mutex;
    std::set<std::thread::id> ids;
    std::set<size_t> workers;
    pool.Run(width, [&](size_t worker) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        ids.insert(std::this_thread::get_id());
        workers.insert(worker);
      }
      for (size_t i = next.fetch_add(1); i < hits.size(); i = next.fetch_add(1)) hits[i]++;
    });
    for (const auto& h : hits) ASSERT_EQ(h.load(), 1) << "width " << width;
    const size_t limit = width == 0 ? 3 : std::min<size_t>(width, 3);
    EXPECT_LE(ids.size(), limit) << "width " << width;
    EXPECT_TRUE(workers.count(0)) << "the caller is worker 0";
    for (size_t w : workers) EXPECT_LT(w, limit);
  }
}

// A request whose caller waits on the pool still finishes while another request holds every pool thread,
// and a Run nested in a body does not deadlock: the caller always works.
TEST(ComputePoolTest, ConcurrentAndNestedRunsFinish) {
  ComputePool pool(2);
  std::atomic<bool> release{false};
  std::atomic<int> blocked_started{0};
  std::thread hog([&] {
    pool.Run(2, [&](size_t) {
      blocked_started++;
      while (!release.load()) std::this_thread::yield();
    });
  });
  while (blocked_started.load() < 2) std::this_thread::yield();  // both the hog's caller and the pool thread
  std::atomic<int> sum{0};
  std::atomic<size_t> next{0};
  pool.Run(2, [&](size_t) {
    for (size_t i = next.fetch_add(1); i < 100; i = next.fetch_add(1)) {
      std::atomic<size_t> inner{0};
      pool.Run(2, [&](size_t) {
        for (size_t j = inner.fetch_add(1); j < 10; j = inner.fetch_add(1)) sum++;
      });
    }
  });
  EXPECT_EQ(sum.load(), 1000);
  release = true;
  hog.join();
}

TEST(ComputePoolTest, OneThreadRunsInlineAndDefaultIsAtLeastOne) {
  ComputePool pool(1);
  const auto caller = std::this_thread::get_id();
  std::thread::id ran;
  pool.Run(4, [&](size_t worker) {
    EXPECT_EQ(worker, 0u);
    ran = std::this_thread::get_id();
  });
  EXPECT_EQ(ran, caller);
  const size_t cores = DefaultComputeThreads();
  EXPECT_GE(cores, 1u);
  EXPECT_LE(cores, std::max(1u, std::thread::hardware_concurrency()));
}

}  // namespace
}  // namespace graspsim
