#include "rpc/sensor_stream.h"

#include "rpc/call.h"
#include "rpc/run_reactor.h"
#include "rpc/sensor_readings.h"
#include "rpc/snapshot_stream.h"
#include "sensors/sensor_registry.h"

namespace graspsim::rpc {
namespace {

// Reads every sensor of the newest state on the pool (View() takes the scene's lock, which must not be taken
// under the stream's mutex), then writes the readings one after the other.
class SensorStream : public SnapshotStream<v1::SensorReading> {
 public:
  SensorStream(grpc::ServerWriteReactor<v1::SensorReading>* reactor, grpc::CallbackServerContext* context,
               std::shared_ptr<Scene> scene, std::vector<std::string> ids, std::chrono::nanoseconds min_interval,
               WorkerPool* pool)
      : SnapshotStream(reactor, std::move(scene), min_interval, "sensor stream"), context_(context),
        ids_(std::move(ids)), pool_(pool) {}

 private:
  void SendLocked(const SceneSnapshot&) override {
    reading_ = true;
    pool_->Post([self = std::static_pointer_cast<SensorStream>(shared_from_this()), last = last_revision_,
                 first = !sent_any_] { self->Read(last, first); });
  }
  bool WriteNextLocked() override {
    if (next_write_ >= batch_.size()) return false;
    WriteLocked(&batch_[next_write_++]);
    return true;
  }
  bool BusyLocked() const override { return reading_; }
  void Read(uint64_t last_revision, bool first);

  grpc::CallbackServerContext* const context_;  // valid while reactor_ is set
  const std::vector<std::string> ids_;
  WorkerPool* const pool_;
  std::vector<v1::SensorReading> batch_;  // one per id; untouched while a write of it is in flight
  size_t next_write_ = 0;
  uint64_t last_revision_ = 0;
  bool sent_any_ = false, reading_ = false;
};

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
        ToProto(ReadSensor(view, FindSensor(view, field, ids_[i]), ids_[i]), &batch[i]);
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
  next_write_ = 0;
  WriteNextLocked();
}

}  // namespace

grpc::ServerWriteReactor<v1::SensorReading>* StartSensorStream(std::shared_ptr<Scene> scene,
                                                               std::vector<std::string> sensor_ids,
                                                               std::chrono::nanoseconds min_interval, WorkerPool* pool,
                                                               grpc::CallbackServerContext* context) {
  auto* reactor = new RunReactor<v1::SensorReading, SensorStream>(context, std::move(scene), std::move(sensor_ids),
                                                                  min_interval, pool);
  reactor->run()->Start();
  return reactor;
}

}  // namespace graspsim::rpc
