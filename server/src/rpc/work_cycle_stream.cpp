#include "rpc/work_cycle_stream.h"

#include <chrono>
#include <deque>
#include <mutex>
#include <optional>

#include "rpc/call.h"
#include "rpc/convert.h"
#include "rpc/run_reactor.h"
#include "rpc/sensor_readings.h"
#include "workcycle/scene_work_cycle.h"

namespace graspsim::rpc {
namespace {

constexpr char kMethod[] = "TactileService/RunWorkCycle";
// Frames simulated ahead of the writer before the simulation pauses: 64 frames are ~150 kB, and a chunk adds
// at most one frame per step (17 at 1 ms steps and 1 kHz frames).
constexpr size_t kMaxBuffered = kMaxFramesPerMessage;

void FrameToProto(const WorkCycle& cycle, const WorkCycleFrame& frame, v1::WorkCycleProgress* out) {
  out->set_stage(StageName(frame.stage));
  out->set_time(frame.time);
  for (size_t i = 0; i < frame.pads.size(); ++i) {
    v1::SensorReading* reading = out->add_readings();
    reading->set_sensor_id(cycle.pad_ids()[i]);
    reading->set_time(frame.time);
    ToProto(frame.pads[i], reading->mutable_tactile());
  }
  v1::SensorReading* gripper = out->add_readings();
  gripper->set_sensor_id(cycle.gripper_id() + "/gripper");
  gripper->set_time(frame.time);
  ToProto(frame.gripper, gripper->mutable_gripper());
  ToProto(frame.object_pose, out->mutable_object_pose());
  out->set_axis_position(frame.axis_position);
  out->set_current_limit(frame.current_limit);
}

// The run's state, shared with the scene's hub and the pool job; it outlives the reactor when one of them
// arrives late, and then does nothing: every use of the reactor checks reactor_ under the mutex.
// Lock order: the hub notifies under the scene's lock, so the scene's lock (View, Update) is never taken while
// holding mutex_.
class WorkCycleRun : public SnapshotWatcher, public std::enable_shared_from_this<WorkCycleRun> {
 public:
  WorkCycleRun(grpc::ServerWriteReactor<v1::WorkCycleProgress>* reactor, grpc::CallbackServerContext* context, std::shared_ptr<Scene> scene,
               WorkCycleRequest request, size_t frames_per_message, SimulationCache* simulations, WorkerPool* pool)
      : reactor_(reactor), context_(context), scene_(std::move(scene)), run_(scene_, std::move(request), simulations),
        frames_per_message_(frames_per_message), pool_(pool), start_(std::chrono::steady_clock::now()) {}

  void Start() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!scene_->snapshots().Subscribe(shared_from_this())) {
      StopLocked(grpc::Status(grpc::StatusCode::NOT_FOUND, "scene_id: scene '" + scene_->id() + "' was deleted"));
      return;
    }
    PumpLocked();
  }
  void OnSnapshotAvailable() override {}  // the run makes the snapshots; it only listens for the hub closing
  void OnHubClosed(const std::string& reason) override {
    std::lock_guard<std::mutex> lock(mutex_);
    StopLocked(grpc::Status(grpc::StatusCode::UNAVAILABLE, reason + "; the work cycle stopped"));
  }
  void OnWriteDone(bool ok) {
    std::lock_guard<std::mutex> lock(mutex_);
    writing_ = false;
    if (!ok) StopLocked(grpc::Status(grpc::StatusCode::CANCELLED, "the work cycle's reader went away"));
    PumpLocked();
  }
  void OnCancel() {
    std::lock_guard<std::mutex> lock(mutex_);
    StopLocked(grpc::Status(grpc::StatusCode::CANCELLED, "work cycle cancelled"));
  }
  void Detach() {
    scene_->snapshots().Unsubscribe(this);
    std::lock_guard<std::mutex> lock(mutex_);
    reactor_ = nullptr;
  }

 private:
  void Simulate();
  // Writes the next frame, finishes when everything is written and the run has ended, or schedules the next
  // chunk while the buffer has room.
  void PumpLocked();
  // Ends the run early: frames not yet written are dropped.
  void StopLocked(grpc::Status status) {
    if (finished_) return;
    pending_.clear();
    end_ = std::make_unique<grpc::Status>(std::move(status));
    PumpLocked();
  }

  std::mutex mutex_;
  grpc::ServerWriteReactor<v1::WorkCycleProgress>* reactor_;
  grpc::CallbackServerContext* const context_;  // valid while reactor_ is set
  const std::shared_ptr<Scene> scene_;
  SceneWorkCycle run_;  // only the one pool job in flight touches it
  const size_t frames_per_message_;
  WorkerPool* const pool_;
  const std::chrono::steady_clock::time_point start_;
  std::deque<v1::WorkCycleProgress> pending_;
  v1::WorkCycleProgress message_;     // the frame being written; untouched until its write completes
  bool writing_ = false, simulating_ = false, finished_ = false;
  std::unique_ptr<grpc::Status> end_;  // set when no chunk follows: finish with it once pending_ is written
};

void WorkCycleRun::PumpLocked() {
  if (!reactor_ || finished_) return;
  if (!writing_ && !pending_.empty()) {
    message_ = std::move(pending_.front());
    pending_.pop_front();
    // The frames that waited meanwhile ride along (a reader slower than the simulation pays one message's
    // overhead for several frames); none is held back for a fuller message.
    while (!pending_.empty() && static_cast<size_t>(message_.following_size()) + 1 < frames_per_message_) {
      *message_.add_following() = std::move(pending_.front());
      pending_.pop_front();
    }
    writing_ = true;
    reactor_->StartWrite(&message_);
  }
  if (!writing_ && pending_.empty() && end_) {
    // A pool job still in flight finds finished_ and drops its chunk.
    finished_ = true;
    LogRequest(kMethod, *context_, *end_, std::chrono::steady_clock::now() - start_);
    reactor_->Finish(*end_);
    return;
  }
  if (!simulating_ && !end_ && pending_.size() < kMaxBuffered) {
    simulating_ = true;
    pool_->Post([self = shared_from_this()] { self->Simulate(); });
  }
}

void WorkCycleRun::Simulate() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!reactor_ || finished_ || end_) {
      simulating_ = false;
      return;
    }
  }
  std::vector<WorkCycleFrame> frames;
  grpc::Status status;
  bool done = false;
  try {
    run_.Advance(&frames, kMaxBuffered / 2);
    done = run_.done();
  } catch (const Error& error) {
    status = ToStatus(error);
  } catch (const std::bad_alloc&) {
    status = grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, std::string(kMethod) + ": out of memory");
  } catch (const std::exception& error) {
    status = grpc::Status(grpc::StatusCode::INTERNAL, std::string(kMethod) + ": " + error.what());
  }
  std::vector<v1::WorkCycleProgress> messages(frames.size());
  for (size_t i = 0; i < frames.size(); ++i) FrameToProto(*run_.cycle(), frames[i], &messages[i]);

  std::lock_guard<std::mutex> lock(mutex_);
  simulating_ = false;
  if (!reactor_ || finished_ || end_) return;  // stopped meanwhile: this chunk is not sent
  for (auto& message : messages) pending_.push_back(std::move(message));
  if (!status.ok()) {
    end_ = std::make_unique<grpc::Status>(status);
  } else if (done) {
    end_ = std::make_unique<grpc::Status>(grpc::Status::OK);
  }
  PumpLocked();
}

}  // namespace

grpc::ServerWriteReactor<v1::WorkCycleProgress>* StartWorkCycleStream(std::shared_ptr<Scene> scene,
                                                                      WorkCycleRequest request,
                                                                      size_t frames_per_message,
                                                                      SimulationCache* simulations, WorkerPool* pool,
                                                                      grpc::CallbackServerContext* context) {
  auto* reactor = new RunReactor<v1::WorkCycleProgress, WorkCycleRun>(context, std::move(scene), std::move(request),
                                                                      frames_per_message, simulations, pool);
  reactor->run()->Start();
  return reactor;
}

}  // namespace graspsim::rpc
