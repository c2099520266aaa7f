#include "core/compute_pool.h"

#include <sched.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <string>

namespace graspsim {
namespace {

size_t configured_threads = 0;  // 0: DefaultComputeThreads()

// "max 100000" (no quota) or "<quota> <period>" in microseconds.
size_t CgroupQuotaCores() {
  std::ifstream file("/sys/fs/cgroup/cpu.max");
  std::string quota;
  double period = 0;
  if (!(file >> quota >> period) || quota == "max" || period <= 0) return 0;
  try {
    return static_cast<size_t>(std::max(1.0, std::ceil(std::stod(quota) / period)));
  } catch (const std::exception&) {
    return 0;
  }
}

}  // namespace

size_t DefaultComputeThreads() {
  cpu_set_t set;
  size_t cores = std::max(1u, std::thread::hardware_concurrency());
  if (sched_getaffinity(0, sizeof(set), &set) == 0) cores = std::max(1, CPU_COUNT(&set));
  const size_t quota = CgroupQuotaCores();
  return quota > 0 ? std::min(cores, quota) : cores;
}

ComputePool::ComputePool(size_t threads) {
  for (size_t i = 1; i < std::max<size_t>(threads, 1); ++i) helpers_.emplace_back([this] { Loop(); });
}

ComputePool::~ComputePool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : helpers_) t.join();
}

void ComputePool::Loop() {
  for (;;) {
    std::function<void()> task;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;
      task = std::move(queue_.front());
      queue_.pop_front();
    }
    task();
  }
}

void ComputePool::Run(size_t width, const std::function<void(size_t worker)>& body) {
  width = std::min(width == 0 ? threads() : width, threads());
  if (width <= 1) {
    body(0);
    return;
  }
  // Shared with the queued tasks, which may outlive this call when dropped (they then only see `closed`).
  struct Join {
    std::mutex mutex;
    std::condition_variable idle;
    bool closed = false;
    size_t running = 0;
  };
  auto join = std::make_shared<Join>();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (size_t worker = 1; worker < width; ++worker) {
      queue_.push_back([join, worker, &body] {
        {
          std::lock_guard<std::mutex> state(join->mutex);
          if (join->closed) return;
          ++join->running;
        }
        body(worker);
        std::lock_guard<std::mutex> state(join->mutex);
        if (--join->running == 0) join->idle.notify_all();
      });
    }
  }
  wake_.notify_all();
  body(0);
  std::unique_lock<std::mutex> lock(join->mutex);
  join->closed = true;
  join->idle.wait(lock, [&] { return join->running == 0; });
}

ComputePool& ComputePool::Shared() {
  static ComputePool pool(configured_threads > 0 ? configured_threads : DefaultComputeThreads());
  return pool;
}

void ComputePool::Configure(size_t threads) { configured_threads = threads; }

}  // namespace graspsim
