// The skeleton every "newest state, at most once per interval" server stream shares (WatchScene,
// TactileService.Stream): a watcher of the scene's snapshot hub behind a callback-API write reactor
// (rpc/run_reactor.h). It
// subscribes, gates sends to the reader's rate with an alarm, never has a write and a finish in flight at once,
// and outlives its reactor when a late notification, alarm or pool job arrives (it then does nothing: every use
// of the reactor checks reactor_ under the mutex).
//
// Lock order: the hub notifies while the scene's lock is held, so nothing here takes the scene's lock (View())
// while holding mutex_.
#pragma once

#include <algorithm>
#include <chrono>
#include <memory>
#include <mutex>
#include <string>

#include <grpcpp/alarm.h>
#include <grpcpp/grpcpp.h>

#include "world/scene.h"

namespace graspsim::rpc {

template <typename Message>
class SnapshotStream : public SnapshotWatcher, public std::enable_shared_from_this<SnapshotStream<Message>> {
 public:
  // `what` names the stream in its end statuses ("watch", "sensor stream").
  SnapshotStream(grpc::ServerWriteReactor<Message>* reactor, std::shared_ptr<Scene> scene,
                 std::chrono::nanoseconds min_interval, std::string what)
      : reactor_(reactor), scene_(std::move(scene)), min_interval_(min_interval), what_(std::move(what)) {}

  // Subscribes and sends the first state at once.
  void Start() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!scene_->snapshots().Subscribe(this->shared_from_this())) {
      FinishLocked(grpc::Status(grpc::StatusCode::NOT_FOUND, "scene_id: scene '" + scene_->id() + "' was deleted"));
      return;
    }
    TrySendLocked();
  }
  // Called on the publishing thread, the simulation's, under the scene's lock: the send (a message built for
  // this reader, its write) runs later on a gRPC thread, so fifty watchers cost the simulation fifty alarms per
  // snapshot rather than fifty messages.
  void OnSnapshotAvailable() override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!reactor_ || finished_ || write_in_flight_ || alarm_pending_ || BusyLocked()) return;
    SendAtLocked(std::max(std::chrono::steady_clock::now(), next_send_));
  }
  void OnHubClosed(const std::string& reason) override {
    std::lock_guard<std::mutex> lock(mutex_);
    FinishLocked(grpc::Status(grpc::StatusCode::UNAVAILABLE, reason));
  }
  void OnWriteDone(bool ok) {
    std::lock_guard<std::mutex> lock(mutex_);
    write_in_flight_ = false;
    if (!reactor_) return;
    if (finish_pending_) {
      FinishLocked(*finish_pending_);
      return;
    }
    if (!ok) {
      FinishLocked(grpc::Status(grpc::StatusCode::CANCELLED, what_ + ": the reader went away"));
      return;
    }
    if (!WriteNextLocked()) TrySendLocked();
  }
  void OnCancel() {
    std::lock_guard<std::mutex> lock(mutex_);
    FinishLocked(grpc::Status(grpc::StatusCode::CANCELLED, what_ + " cancelled"));
  }
  void Detach() {
    scene_->snapshots().Unsubscribe(this);
    std::lock_guard<std::mutex> lock(mutex_);
    reactor_ = nullptr;
  }

 protected:
  // Under mutex_: a snapshot newer than the last one sent may go out now (the rate gate has passed): start its
  // write (WriteLocked) or the work that leads to one.
  virtual void SendLocked(const SceneSnapshot& snapshot) = 0;
  // Under mutex_, after a write completed: starts the next write of a batch and returns true, or returns false
  // when the batch is done.
  virtual bool WriteNextLocked() { return false; }
  // Under mutex_: work of the last send still under way (no new send starts meanwhile).
  virtual bool BusyLocked() const { return false; }

  void WriteLocked(const Message* message) {
    write_in_flight_ = true;
    reactor_->StartWrite(message);
  }
  // Newest snapshot, rate-gated: sends it now, or sets an alarm for when this reader's rate allows.
  void TrySendLocked() {
    if (!reactor_ || finished_ || write_in_flight_ || alarm_pending_ || BusyLocked()) return;
    const std::shared_ptr<const SceneSnapshot> snapshot = scene_->snapshots().Latest();
    if (!snapshot || snapshot->sequence <= last_sequence_) return;
    const auto now = std::chrono::steady_clock::now();
    if (now < next_send_) {
      SendAtLocked(next_send_);
      return;
    }
    last_sequence_ = snapshot->sequence;
    next_send_ = now + min_interval_;
    SendLocked(*snapshot);
  }
  // An alarm that tries the send again at `when` (at once, on a gRPC thread, when `when` has passed).
  void SendAtLocked(std::chrono::steady_clock::time_point when) {
    alarm_pending_ = true;
    alarm_ = std::make_unique<grpc::Alarm>();
    alarm_->Set(std::chrono::system_clock::now() + (when - std::chrono::steady_clock::now()),
                [self = this->shared_from_this()](bool) {
                  std::lock_guard<std::mutex> lock(self->mutex_);
                  self->alarm_pending_ = false;
                  self->TrySendLocked();
                });
  }
  // Finishing waits for an outstanding write, so the reactor never has a write and a finish in flight at once.
  void FinishLocked(grpc::Status status) {
    if (!reactor_ || finished_) return;
    if (write_in_flight_) {
      if (!finish_pending_) finish_pending_ = std::make_unique<grpc::Status>(std::move(status));
      return;
    }
    finished_ = true;
    reactor_->Finish(status);
  }

  std::mutex mutex_;
  grpc::ServerWriteReactor<Message>* reactor_;  // null once the reactor is done (Detach)
  const std::shared_ptr<Scene> scene_;
  bool finished_ = false;

 private:
  const std::chrono::nanoseconds min_interval_;
  const std::string what_;
  uint64_t last_sequence_ = 0;
  std::chrono::steady_clock::time_point next_send_ = {};
  bool write_in_flight_ = false, alarm_pending_ = false;
  std::unique_ptr<grpc::Status> finish_pending_;
  std::unique_ptr<grpc::Alarm> alarm_;
};

}  // namespace graspsim::rpc
