#include "rpc/sensor_stream.h"

#include <mutex>

#include <grpcpp/alarm.h>

#include "rpc/call.h"
#include "rpc/sensor_readings.h"

namespace graspsim::rpc {
namespace {

class SensorReactor;

// The stream's state, shared with the scene's hub, the alarm and the pool job; it outlives the reactor when one
// of them arrives late, and then does nothing: every use of the reactor checks reactor_ under the mutex.
//
// Lock order: the hub notifies while the scene's lock is held, so nothing here takes the scene's lock (View())
// while holding mutex_; View() runs on the pool, outside mutex_.
class SensorStream : public SnapshotWatcher, public std::enable_shared_from_this<SensorStream> {
 public:
  SensorStream(SensorReactor* reactor, grpc::CallbackServerContext* context, std::shared_ptr<Scene> scene,
               std::vector<std::string> ids, std::chrono::nanoseconds min_interval, WorkerPool* pool)
      : reactor_(reactor), context_(context), scene_(std::move(scene)), ids_(std::move(ids)),
        min_interval_(min_interval), pool_(pool) {}

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
    FinishLocked(grpc::Status(grpc::StatusCode::CANCELLED, "sensor stream cancelled"));
  }
  void Detach() {
    scene_->snapshots().Unsubscribe(this);
    std::lock_guard<std::mutex> lock(mutex_);
    reactor_ = nullptr;
  }

 private:
  void TrySendLocked();
  // On the pool: reads every sensor in the newest state, then starts writing them.
  void Read(uint64_t last_revision, bool first);
  // Finishing waits for an outstanding write, so the reactor never has a write and a finish in flight at once.
  void FinishLocked(grpc::Status status);

  std::mutex mutex_;
  SensorReactor* reactor_;
  grpc::CallbackServerContext* const context_;  // valid while reactor_ is set
  const std::shared_ptr<Scene> scene_;
  const std::vector<std::string> ids_;
  const std::chrono::nanoseconds min_interval_;
  WorkerPool* const pool_;
  std::vector<v1::SensorReading> batch_;  // one per id; untouched while a write of it is in flight
  size_t next_write_ = 0;
  uint64_t last_sequence_ = 0, last_revision_ = 0;
  bool sent_any_ = false;
  std::chrono::steady_clock::time_point next_send_ = {};
  bool reading_ = false, write_in_flight_ = false, alarm_pending_ = false, finished_ = false;
  std::unique_ptr<grpc::Status> finish_pending_;
  std::unique_ptr<grpc::Alarm> alarm_;
};

class SensorReactor : public grpc::ServerWriteReactor<v1::SensorReading> {
 public:
  SensorReactor(grpc::CallbackServerContext* context, std::shared_ptr<Scene> scene, std::vector<std::string> ids,
                std::chrono::nanoseconds min_interval, WorkerPool* pool)
      : stream_(std::make_shared<SensorStream>(this, context, std::move(scene), std::move(ids), min_interval, pool)) {
    stream_->Start();
  }
  void OnWriteDone(bool ok) override { stream_->OnWriteDone(ok); }
  void OnCancel() override { stream_->OnCancel(); }
  void OnDone() override {
    stream_->Detach();
    delete this;
  }

 private:
  std::shared_ptr<SensorStream> stream_;
};

void SensorStream::Start() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!scene_->snapshots().Subscribe(shared_from_this())) {
    FinishLocked(grpc::Status(grpc::StatusCode::NOT_FOUND, "scene_id: scene '" + scene_->id() + "' was deleted"));
    return;
  }
  TrySendLocked();  // the first readings at once; the ids are checked by that first read
}

void SensorStream::TrySendLocked() {
  if (!reactor_ || finished_ || reading_ || write_in_flight_ || alarm_pending_) return;
  const std::shared_ptr<const SceneSnapshot> snapshot = scene_->snapshots().Latest();
  if (!snapshot || snapshot->sequence <= last_sequence_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now < next_send_) {
    // Too soon for this reader's rate: come back when allowed and read whatever is newest then.
    alarm_pending_ = true;
    alarm_ = std::make_unique<grpc::Alarm>();
    alarm_->Set(std::chrono::system_clock::now() + (next_send_ - now), [self = shared_from_this()](bool) {
      std::lock_guard<std::mutex> lock(self->mutex_);
      self->alarm_pending_ = false;
      self->TrySendLocked();
    });
    return;
  }
  last_sequence_ = snapshot->sequence;
  next_send_ = now + min_interval_;
  reading_ = true;
  pool_->Post([self = shared_from_this(), last = last_revision_, first = !sent_any_] { self->Read(last, first); });
}

void SensorStream::Read(uint64_t last_revision, bool first) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<v1::SensorReading> batch;
  uint64_t revision = last_revision;
  grpc::Status status;
  try {
    const SceneView view = scene_->View();
    revision = view.revision;
    // Several snapshots may have been taken in one View: a state already sent is not sent again.
    if (first || view.revision != last_revision) {
      batch.resize(ids_.size());
      for (size_t i = 0; i < ids_.size(); ++i) {
        const std::string field = "sensor_ids[" + std::to_string(i) + "]";
        ReadSensor(view, FindSensor(view, field, ids_[i]), ids_[i], &batch[i]);
      }
    }
  } catch (const Error& error) {
    status = ToStatus(error);
  } catch (const std::exception& error) {
    status = grpc::Status(grpc::StatusCode::INTERNAL, std::string("TactileService/Stream: ") + error.what());
  }
  std::lock_guard<std::mutex> lock(mutex_);
  reading_ = false;
  if (!reactor_ || finished_) return;
  if (!status.ok()) {
    // A bad id on the first read is the request's error; later, a sensor's robot was removed.
    if (first) LogRequest("TactileService/Stream", *context_, status, std::chrono::steady_clock::now() - start);
    FinishLocked(status);
    return;
  }
  if (batch.empty()) {
    TrySendLocked();
    return;
  }
  batch_ = std::move(batch);
  last_revision_ = revision;
  sent_any_ = true;
  next_write_ = 1;
  write_in_flight_ = true;
  reactor_->StartWrite(&batch_[0]);
}

void SensorStream::OnWriteDone(bool ok) {
  std::lock_guard<std::mutex> lock(mutex_);
  write_in_flight_ = false;
  if (!reactor_) return;
  if (finish_pending_) {
    FinishLocked(*finish_pending_);
    return;
  }
  if (!ok) {
    FinishLocked(grpc::Status(grpc::StatusCode::CANCELLED, "sensor reader went away"));
    return;
  }
  if (next_write_ < batch_.size()) {
    write_in_flight_ = true;
    reactor_->StartWrite(&batch_[next_write_++]);
    return;
  }
  TrySendLocked();
}

void SensorStream::FinishLocked(grpc::Status status) {
  if (!reactor_ || finished_) return;
  if (write_in_flight_) {
    if (!finish_pending_) finish_pending_ = std::make_unique<grpc::Status>(std::move(status));
    return;
  }
  finished_ = true;
  reactor_->Finish(status);
}

}  // namespace

grpc::ServerWriteReactor<v1::SensorReading>* StartSensorStream(std::shared_ptr<Scene> scene,
                                                               std::vector<std::string> sensor_ids,
                                                               std::chrono::nanoseconds min_interval, WorkerPool* pool,
                                                               grpc::CallbackServerContext* context) {
  return new SensorReactor(context, std::move(scene), std::move(sensor_ids), min_interval, pool);
}

}  // namespace graspsim::rpc
