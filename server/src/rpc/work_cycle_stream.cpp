#include "rpc/work_cycle_stream.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <mutex>
#include <optional>

#include "rpc/call.h"
#include "rpc/convert.h"
#include "rpc/run_reactor.h"
#include "rpc/sensor_readings.h"

namespace graspsim::rpc {
namespace {

constexpr char kMethod[] = "TactileService/RunWorkCycle";
// Frames simulated ahead of the writer before the simulation pauses: 64 frames are ~150 kB, and a chunk adds
// at most one frame per step (17 at 1 ms steps and 1 kHz frames).
constexpr size_t kMaxBuffered = kMaxFramesPerMessage;
// Wall time one scene update may run chunks for: viewers still get a commit every few milliseconds.
constexpr auto kChunkWallTime = std::chrono::milliseconds(4);
// How much wall time of a long cycle a crash may lose at most.
constexpr auto kCheckpointInterval = std::chrono::seconds(1);

// As StepSimulation: the cycle advances in chunks of 1/60 s of simulated time, and the scene's writers' lock is
// released and the state committed between updates (at least every kChunkWallTime), so viewers (WatchScene) see the cycle
// and other requests are served.
uint64_t StepsPerChunk(const SimulationParams& params) {
  return std::max<uint64_t>(1, static_cast<uint64_t>(std::lround((1.0 / 60) / params.time_step)));
}

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
      : reactor_(reactor), context_(context), scene_(std::move(scene)), request_(std::move(request)),
        frames_per_message_(frames_per_message), simulations_(simulations), pool_(pool),
        start_(std::chrono::steady_clock::now()) {}

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
  const WorkCycleRequest request_;
  const size_t frames_per_message_;
  SimulationCache* const simulations_;
  WorkerPool* const pool_;
  const std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_checkpoint_ = start_;  // pool jobs run one at a time
  std::unique_ptr<WorkCycle> cycle_;  // only the one pool job in flight touches it
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
    if (!cycle_) {  // the request against the scene as it is now; errors end the stream before any frame
      const SceneView view = scene_->View();
      cycle_ = std::make_unique<WorkCycle>(view.model, view.state, request_);
    }
    std::optional<Error> failure;
    scene_->Update([&](const std::shared_ptr<const SceneModel>& model, SceneState* state) {
      try {
        // 1/60 s chunks of simulated time while they take less than kChunkWallTime together (a fast cycle at
        // 100 × real time would otherwise commit and hop threads 6000 times a second) and the frames fit half
        // the buffer. The frames do not depend on the chunking.
        // Held, not borrowed: a DeleteScene meanwhile drops the cache's entry (a cancelled cycle's scene deleted at
        // once freed the engine under this loop: a crash).
        const std::shared_ptr<PhysicsEngine> simulation = simulations_->For(scene_->id(), model);
        const auto until = std::chrono::steady_clock::now() + kChunkWallTime;
        for (;;) {
          cycle_->Advance(simulation.get(), state, StepsPerChunk(model->simulation), &frames);
          if (cycle_->done() || frames.size() >= kMaxBuffered / 2 || std::chrono::steady_clock::now() >= until) break;
          scene_->PublishDuringUpdate(*state);  // a recording gets every chunk, not only the committed ones
        }
      } catch (const Error& error) {
        failure = error;  // commit the steps done before it: the scene then matches the frames sent
      }
    }, /*journal=*/false);
    done = cycle_->done();
    // The state is stored at the end of the cycle (before its last frame is sent), when it fails, and every
    // kCheckpointInterval of a long cycle, not per chunk (docs/durability.md).
    const auto now = std::chrono::steady_clock::now();
    if (done || failure || now - last_checkpoint_ > kCheckpointInterval) {
      scene_->Checkpoint();
      last_checkpoint_ = now;
    }
    if (failure) throw *failure;
  } catch (const Error& error) {
    status = ToStatus(error);
  } catch (const std::bad_alloc&) {
    status = grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, std::string(kMethod) + ": out of memory");
  } catch (const std::exception& error) {
    status = grpc::Status(grpc::StatusCode::INTERNAL, std::string(kMethod) + ": " + error.what());
  }
  std::vector<v1::WorkCycleProgress> messages(frames.size());
  for (size_t i = 0; i < frames.size(); ++i) FrameToProto(*cycle_, frames[i], &messages[i]);

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
