#include "recording/frame_tap.h"

#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "core/error.h"
#include "core/log.h"

namespace graspsim::recording {
namespace {

constexpr int kWriterNice = 10;

}  // namespace

FrameTap::FrameTap(std::shared_ptr<Scene> scene, std::unique_ptr<FrameConsumer> consumer, double interval,
                   size_t max_queued)
    : scene_(std::move(scene)), consumer_(std::move(consumer)), interval_(interval), max_queued_(max_queued) {}

FrameTap::~FrameTap() {
  if (thread_.joinable()) Stop();
}

void FrameTap::Start() {
  scene_->snapshots().WantDetail(true, interval_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto first = scene_->DetailedSnapshot();
    last_sequence_ = first->sequence;
    last_queued_ = first;
    queue_.push_back(std::move(first));
  }
  subscribed_ = scene_->snapshots().Subscribe(shared_from_this());
  if (!subscribed_) stopping_ = true;  // the scene is being deleted: record what it was
  thread_ = std::thread([this] { Run(); });
}

void FrameTap::OnSnapshotAvailable() {
  auto snapshot = scene_->snapshots().Latest();
  std::lock_guard<std::mutex> lock(mutex_);
  // Detail is asked for before subscribing, but a publication racing the request may come without it; and a
  // state already queued (the first frame) is not queued twice.
  if (!snapshot || !snapshot->state || snapshot->sequence <= last_sequence_ || stopping_) return;
  last_sequence_ = snapshot->sequence;
  const double since = snapshot->time - last_queued_->time;
  if (since >= 0 && since < interval_ - 1e-9 && snapshot->model == last_queued_->model &&
      snapshot->edits == last_queued_->edits) {
    skipped_ = std::move(snapshot);
    return;
  }
  QueueLocked(std::move(snapshot));
}

void FrameTap::QueueLocked(std::shared_ptr<const SceneSnapshot> snapshot) {
  skipped_.reset();
  if (queue_.size() >= max_queued_) {
    ++dropped_;
    return;
  }
  last_queued_ = snapshot;
  queue_.push_back(std::move(snapshot));
  if (waiting_) wake_.notify_one();  // a writer at work finds the frame without a wake-up (a system call here)
}

void FrameTap::OnHubClosed(const std::string&) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (skipped_ && !stopping_) QueueLocked(std::move(skipped_));
  stopping_ = true;
  wake_.notify_one();
}

void FrameTap::Run() {
  // Below the simulation's threads: on a busy machine the writer yields the CPU and catches up when it is free
  // (its queue holds the frames meanwhile), so that recording costs the simulation as little as it can.
  setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), kWriterNice);
  for (;;) {
    std::shared_ptr<const SceneSnapshot> frame;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      const auto ready = [&] { return !queue_.empty() || stopping_; };
      const auto idle = consumer_->idle_interval();
      waiting_ = true;
      if (idle.count() == 0) {
        wake_.wait(lock, ready);
        waiting_ = false;
      } else if (!wake_.wait_for(lock, idle, ready)) {
        waiting_ = false;
        lock.unlock();
        frame = scene_->DetailedSnapshot();  // idle: the current state again
      } else {
        waiting_ = false;
      }
      if (!frame) {
        if (queue_.empty()) break;
        frame = std::move(queue_.front());
        queue_.pop_front();
      }
    }
    try {
      consumer_->Consume(*frame);
    } catch (const std::exception& error) {  // a full disk: end the tap, keep the simulation running
      std::lock_guard<std::mutex> lock(mutex_);
      error_ = error.what();
      stopping_ = true;
      queue_.clear();
      Log(LogLevel::kError, "frame consumer failed", {{"scene", scene_->id()}, {"error", error_}});
      break;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    ++frames_;
  }
  try {
    consumer_->Finish();
  } catch (const std::exception& error) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (error_.empty()) error_ = error.what();
  }
  timespec cpu{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cpu);
  std::lock_guard<std::mutex> lock(mutex_);
  finished_ = true;
  // What the tap cost the machine: its thread's CPU time over all its frames.
  Log(LogLevel::kInfo, "frame tap finished",
      {{"scene", scene_->id()}, {"frames", std::to_string(frames_)}, {"dropped", std::to_string(dropped_)},
       {"cpu_s", std::to_string(static_cast<double>(cpu.tv_sec) + 1e-9 * static_cast<double>(cpu.tv_nsec))}});
}

bool FrameTap::finished() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return finished_;
}

std::string FrameTap::Stop() {
  if (subscribed_) scene_->snapshots().Unsubscribe(this);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (skipped_ && !stopping_) QueueLocked(std::move(skipped_));  // the state the recording ends on
    stopping_ = true;
    wake_.notify_one();
  }
  if (thread_.joinable()) {
    thread_.join();
    scene_->snapshots().WantDetail(false, interval_);
  }
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

uint64_t FrameTap::frames() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return frames_;
}

uint64_t FrameTap::dropped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_;
}

}  // namespace graspsim::recording
