#include "rpc/watch_scene.h"

#include <mutex>

#include <grpcpp/alarm.h>

#include "rpc/failed_call.h"

namespace graspsim::rpc {
namespace {

class WatchReactor;

// The watcher the scene's hub knows. It outlives the reactor when a late notification or alarm arrives, and
// then does nothing: every use of the reactor checks reactor_ under the mutex.
class SnapshotStream : public SnapshotWatcher, public std::enable_shared_from_this<SnapshotStream> {
 public:
  SnapshotStream(WatchReactor* reactor, std::shared_ptr<Scene> scene, std::chrono::nanoseconds min_interval)
      : reactor_(reactor), scene_(std::move(scene)), min_interval_(min_interval) {}

  void Start();
  void OnSnapshotAvailable() override {
    std::lock_guard<std::mutex> lock(mutex_);
    TrySendLocked();
  }
  void OnHubClosed(const std::string& reason) override {
    std::lock_guard<std::mutex> lock(mutex_);
    FinishLocked(grpc::Status(grpc::StatusCode::UNAVAILABLE, reason));
  }
  void OnWriteDone(bool ok);
  void OnCancel() {
    std::lock_guard<std::mutex> lock(mutex_);
    FinishLocked(grpc::Status(grpc::StatusCode::CANCELLED, "watch cancelled"));
  }
  void Detach() {
    scene_->snapshots().Unsubscribe(this);
    std::lock_guard<std::mutex> lock(mutex_);
    reactor_ = nullptr;
  }

 private:
  void TrySendLocked();
  // Finishing waits for an outstanding write, so the reactor never has a write and a finish in flight at once.
  void FinishLocked(grpc::Status status);

  std::mutex mutex_;
  WatchReactor* reactor_;
  const std::shared_ptr<Scene> scene_;
  const std::chrono::nanoseconds min_interval_;
  v1::SceneSnapshot message_;  // must stay untouched while a write is in flight
  uint64_t last_sent_sequence_ = 0;
  std::chrono::steady_clock::time_point next_send_ = {};
  bool write_in_flight_ = false, alarm_pending_ = false, finished_ = false;
  std::unique_ptr<grpc::Status> finish_pending_;
  std::unique_ptr<grpc::Alarm> alarm_;
};

class WatchReactor : public grpc::ServerWriteReactor<v1::SceneSnapshot> {
 public:
  WatchReactor(std::shared_ptr<Scene> scene, std::chrono::nanoseconds min_interval)
      : stream_(std::make_shared<SnapshotStream>(this, std::move(scene), min_interval)) {
    stream_->Start();
  }
  void OnWriteDone(bool ok) override { stream_->OnWriteDone(ok); }
  void OnCancel() override { stream_->OnCancel(); }
  void OnDone() override {
    stream_->Detach();
    delete this;
  }

 private:
  std::shared_ptr<SnapshotStream> stream_;
};

void SnapshotStream::Start() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!scene_->snapshots().Subscribe(shared_from_this())) {
    FinishLocked(grpc::Status(grpc::StatusCode::NOT_FOUND, "scene_id: scene '" + scene_->id() + "' was deleted"));
    return;
  }
  TrySendLocked();  // the first snapshot at once
}

void SnapshotStream::OnWriteDone(bool ok) {
  std::lock_guard<std::mutex> lock(mutex_);
  write_in_flight_ = false;
  if (finish_pending_) {
    FinishLocked(*finish_pending_);
    return;
  }
  if (!ok) {
    FinishLocked(grpc::Status(grpc::StatusCode::CANCELLED, "watcher went away"));
    return;
  }
  TrySendLocked();
}

void SnapshotStream::TrySendLocked() {
  if (!reactor_ || finished_ || write_in_flight_ || alarm_pending_) return;
  const std::shared_ptr<const SceneSnapshot> snapshot = scene_->snapshots().Latest();
  if (!snapshot || snapshot->sequence <= last_sent_sequence_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now < next_send_) {
    // Too soon for this watcher's rate: come back when allowed and send whatever is newest then.
    alarm_pending_ = true;
    alarm_ = std::make_unique<grpc::Alarm>();
    alarm_->Set(std::chrono::system_clock::now() + (next_send_ - now), [self = shared_from_this()](bool) {
      std::lock_guard<std::mutex> lock(self->mutex_);
      self->alarm_pending_ = false;
      self->TrySendLocked();
    });
    return;
  }
  message_.Clear();
  message_.set_sequence(snapshot->sequence);
  message_.set_revision(snapshot->revision);
  message_.set_time(snapshot->time);
  for (const auto& id : *snapshot->body_ids) message_.add_body_ids(id);
  message_.set_body_poses(snapshot->body_poses.data(), snapshot->body_poses.size() * sizeof(double));
  for (const auto& id : *snapshot->joint_ids) message_.add_joint_ids(id);
  message_.set_joint_positions(snapshot->joint_positions.data(), snapshot->joint_positions.size() * sizeof(double));
  last_sent_sequence_ = snapshot->sequence;
  next_send_ = now + min_interval_;
  write_in_flight_ = true;
  reactor_->StartWrite(&message_);
}

void SnapshotStream::FinishLocked(grpc::Status status) {
  if (!reactor_ || finished_) return;
  if (write_in_flight_) {
    if (!finish_pending_) finish_pending_ = std::make_unique<grpc::Status>(std::move(status));
    return;
  }
  finished_ = true;
  reactor_->Finish(status);
}

}  // namespace

grpc::ServerWriteReactor<v1::SceneSnapshot>* StartWatch(std::shared_ptr<Scene> scene,
                                                        std::chrono::nanoseconds min_interval) {
  return new WatchReactor(std::move(scene), min_interval);
}

grpc::ServerWriteReactor<v1::SceneSnapshot>* FailedWatch(const grpc::Status& status) {
  return new FailedWriter<v1::SceneSnapshot>(status);
}

}  // namespace graspsim::rpc
