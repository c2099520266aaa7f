// The threads every parallel stage of a request draws from (grasp planning, its hull volumes, mesh parsing): one
// pool per process, sized by --compute-threads (default: the cores this process may use, container quota
// included), so that a replica on a 16-core node uses 16 and one given 1 core uses 1.
//
// Fairness: the thread that calls Run always works on its own request, so no request waits for another to
// finish; the pool's threads join requests in the order they asked (FIFO). One request alone gets all
// `threads()`; k concurrent requests share them (each has its caller, helpers go first come first served).
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace graspsim {

class ComputePool {
 public:
  // `threads` >= 1: the width of one request alone (the caller plus threads - 1 pool threads).
  explicit ComputePool(size_t threads);
  ~ComputePool();
  ComputePool(const ComputePool&) = delete;
  ComputePool& operator=(const ComputePool&) = delete;

  size_t threads() const { return helpers_.size() + 1; }

  // Runs body(worker) for worker 0 (this thread) and up to width - 1 more workers from the pool, as threads
  // free up; returns when every started worker has returned. Workers that have not started once worker 0
  // returns are dropped: `body` must share its work through a counter, so that any one worker finishes it all.
  // width 0 = threads().
  void Run(size_t width, const std::function<void(size_t worker)>& body);

  // The process's pool: created on first use with DefaultComputeThreads(), unless Configure came first.
  static ComputePool& Shared();
  // Sets the shared pool's size (the server's --compute-threads); must precede the first Shared().
  static void Configure(size_t threads);

 private:
  void Loop();

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> queue_;
  bool stopping_ = false;
  std::vector<std::thread> helpers_;
};

// The cores this process may run on: its CPU affinity, capped by a cgroup v2 CPU quota (cpu.max), at least 1.
size_t DefaultComputeThreads();

}  // namespace graspsim
