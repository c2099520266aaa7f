#include "recording/frame_tap.h"

#include "core/error.h"
#include "core/log.h"

namespace graspsim::recording {

FrameTap::FrameTap(std::shared_ptr<Scene> scene, std::unique_ptr<FrameConsumer> consumer, size_t max_queued)
    : scene_(std::move(scene)), consumer_(std::move(consumer)), max_queued_(max_queued) {}

FrameTap::~FrameTap() {
  if (thread_.joinable()) Stop();
}

void FrameTap::Start() {
  scene_->snapshots().WantDetail(true);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto first = scene_->DetailedSnapshot();
    last_sequence_ = first->sequence;
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
  if (queue_.size() >= max_queued_) {
    ++dropped_;
    return;
  }
  queue_.push_back(std::move(snapshot));
  wake_.notify_one();
}

void FrameTap::OnHubClosed(const std::string&) {
  std::lock_guard<std::mutex> lock(mutex_);
  stopping_ = true;
  wake_.notify_one();
}

void FrameTap::Run() {
  for (;;) {
    std::shared_ptr<const SceneSnapshot> frame;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      const auto ready = [&] { return !queue_.empty() || stopping_; };
      const auto idle = consumer_->idle_interval();
      if (idle.count() == 0) {
        wake_.wait(lock, ready);
      } else if (!wake_.wait_for(lock, idle, ready)) {
        lock.unlock();
        frame = scene_->DetailedSnapshot();  // idle: the current state again
      }
      if (!frame) {
        if (queue_.empty()) break;
        frame = std::move(queue_.front());
        queue_.pop_front();
      }
    }
    try {
      if (error_.empty()) consumer_->Consume(*frame);
    } catch (const std::exception& error) {  // a full disk: stop recording, keep the simulation running
      std::lock_guard<std::mutex> lock(mutex_);
      error_ = error.what();
      Log(LogLevel::kError, "recording stopped", {{"scene", scene_->id()}, {"error", error_}});
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
  std::lock_guard<std::mutex> lock(mutex_);
  finished_ = true;
}

bool FrameTap::finished() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return finished_;
}

std::string FrameTap::Stop() {
  if (subscribed_) scene_->snapshots().Unsubscribe(this);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    wake_.notify_one();
  }
  if (thread_.joinable()) {
    thread_.join();
    scene_->snapshots().WantDetail(false);
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
