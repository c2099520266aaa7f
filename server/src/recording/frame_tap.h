// A scene's published states handed, in order and each once, to a consumer on a thread of its own: what a
// recording or a live stream needs (the viewers' watchers skip to the newest state instead). The simulation
// never waits for it: when the consumer falls behind by more than the queue holds, new states are dropped and
// counted (Recording.dropped_frames). Frames closer in simulated time than the consumer needs are skipped.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "world/scene.h"

namespace graspsim::recording {

class FrameConsumer {
 public:
  virtual ~FrameConsumer() = default;
  // Each frame carries the model and state (SceneSnapshot::model, ::state). Called on the tap's thread; the
  // first call gets the scene as it was when the tap started. What it throws ends the tap (Stop reports it).
  virtual void Consume(const SceneSnapshot& frame) = 0;
  // After the last frame (Stop, or the scene was deleted).
  virtual void Finish() {}
  // Non-zero: when the scene publishes nothing for this long, the current state is consumed again (a live client
  // that subscribed to an idle scene still gets it).
  virtual std::chrono::milliseconds idle_interval() const { return std::chrono::milliseconds(0); }
};

class FrameTap : public SnapshotWatcher, public std::enable_shared_from_this<FrameTap> {
 public:
  // `interval`: simulated seconds between frames at most this close are skipped (not dropped: the last state
  // before Stop is consumed even so, and a frame with another model or edits is never skipped); 0 = every one.
  FrameTap(std::shared_ptr<Scene> scene, std::unique_ptr<FrameConsumer> consumer, double interval = 0,
           size_t max_queued = 1024);
  ~FrameTap() override;
  // Subscribes and starts the thread with the scene's current state as the first frame.
  void Start();
  // Unsubscribes, consumes what is queued, calls Finish and joins. Returns the consumer's error, if any ("").
  // Not from the consumer's own thread.
  std::string Stop();

  uint64_t frames() const;
  uint64_t dropped() const;
  // The thread has ended by itself (the scene was deleted) or by Stop.
  bool finished() const;
  FrameConsumer& consumer() { return *consumer_; }

  void OnSnapshotAvailable() override;
  void OnHubClosed(const std::string& reason) override;

 private:
  void Run();
  void QueueLocked(std::shared_ptr<const SceneSnapshot> snapshot);

  std::shared_ptr<Scene> scene_;
  std::unique_ptr<FrameConsumer> consumer_;
  const double interval_;
  const size_t max_queued_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::shared_ptr<const SceneSnapshot>> queue_;
  uint64_t last_sequence_ = 0, frames_ = 0, dropped_ = 0;
  std::shared_ptr<const SceneSnapshot> last_queued_, skipped_;  // the newest frame queued, and one skipped since
  bool stopping_ = false, subscribed_ = false, finished_ = false, waiting_ = false;
  std::string error_;
  std::thread thread_;
};

}  // namespace graspsim::recording
