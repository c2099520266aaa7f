#include "rpc/predict_action_stream.h"

#include <deque>
#include <mutex>
#include <optional>

#include <grpcpp/alarm.h>

#include "gateway/action_prediction.h"
#include "rpc/call.h"
#include "rpc/convert_gateway.h"
#include "rpc/failed_call.h"
#include "rpc/run_reactor.h"

namespace graspsim::rpc {
namespace {

constexpr char kMethod[] = "GatewayService/PredictAction";

void ToProto(const gateway::GripperSample& s, v1::GripperPrediction* out) {
  out->set_opening(s.opening);
  out->set_current(s.current);
  out->set_tactile_sum(s.tactile_sum);
}

// The run, shared with the hub's reading subscription, the command's completion, the alarm and pool jobs; it
// outlives its reactor when one of them arrives late and then does nothing (reactor_ is checked under mutex_).
// Lock order: hub callbacks run under the hub's subscription lock and take mutex_; nothing here calls the hub
// while holding mutex_.
class PredictionRun : public std::enable_shared_from_this<PredictionRun> {
 public:
  PredictionRun(grpc::ServerWriteReactor<v1::PredictionSample>* reactor, grpc::CallbackServerContext* context,
                gateway::GatewayHub* hub, WorkerPool* pool)
      : reactor_(reactor), context_(context), hub_(hub), pool_(pool), begun_(std::chrono::steady_clock::now()) {}

  // Validated request; builds the twin on the pool (a Simulation samples surfaces), then starts the action.
  void Start(std::string device_id, gateway::DeviceLimits limits, gateway::Move move, gateway::PredictionTiming timing,
             std::shared_ptr<const SceneModel> model, SceneState state, std::string gripper_id,
             RecordingLog* recordings, std::string scene_id) {
    recordings_ = recordings;
    scene_id_ = std::move(scene_id);
    device_id_ = std::move(device_id);
    limits_ = limits;
    move_ = move;
    gate_ = gateway::SampleGate(timing.rate_hz);
    const double timeout = timing.timeout;
    deadline_alarm_.Set(std::chrono::system_clock::now() + std::chrono::duration_cast<std::chrono::system_clock::duration>(
                                                               std::chrono::duration<double>(timeout)),
                        [self = shared_from_this(), timeout](bool fired) {
                          if (fired) self->TimedOut(timeout);
                        });
    pool_->Post([self = shared_from_this(), model = std::move(model), state = std::move(state),
                 gripper_id = std::move(gripper_id)]() mutable {
      try {
        auto twin = std::make_unique<gateway::SimulatedGripper>(model, std::move(state), gripper_id);
        self->Begin(std::move(twin));
      } catch (const Error& error) {
        std::lock_guard<std::mutex> lock(self->mutex_);
        self->FinishLocked(ToStatus(error));
      }
    });
  }

  void OnWriteDone(bool ok) {
    std::lock_guard<std::mutex> lock(mutex_);
    writing_ = false;
    if (!ok) {
      FinishLocked(grpc::Status(grpc::StatusCode::CANCELLED, "the prediction's reader went away"));
      return;
    }
    if (finish_pending_) {
      FinishLocked(*finish_pending_);
      return;
    }
    WriteNextLocked();
  }
  void OnCancel() {
    std::lock_guard<std::mutex> lock(mutex_);
    FinishLocked(grpc::Status(grpc::StatusCode::CANCELLED, "prediction cancelled"));
  }
  void Detach() {
    uint64_t subscription = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      reactor_ = nullptr;
      subscription = subscription_;
      subscription_ = 0;
    }
    if (subscription != 0) hub_->Unsubscribe(subscription);
    deadline_alarm_.Cancel();
  }

 private:
  void Begin(std::unique_ptr<gateway::SimulatedGripper> twin) {
    std::weak_ptr<PredictionRun> weak = weak_from_this();
    const uint64_t subscription = hub_->Subscribe(device_id_, [weak](const gateway::DeviceReading& reading) {
      if (auto self = weak.lock()) self->OnReading(reading);
    });
    {
      std::lock_guard<std::mutex> lock(mutex_);
      twin_ = std::move(twin);
      subscription_ = subscription;
      if (!reactor_ || finished_) return;  // Detach ran meanwhile; its Unsubscribe missed this subscription
    }
    gateway::Command command;
    command.device_id = device_id_;
    command.kind = gateway::Command::Kind::kMove;
    command.move = move_;
    hub_->Submit(command, [self = shared_from_this()](const gateway::CommandResult& result) { self->OnStarted(result); });
  }

  void OnStarted(const gateway::CommandResult& result) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!result.ok()) {
      FinishLocked(grpc::Status(static_cast<grpc::StatusCode>(result.code), result.message));
      return;
    }
    if (!result.reading) {
      FinishLocked(grpc::Status(grpc::StatusCode::INTERNAL, "the gateway's result carries no reading"));
      return;
    }
    // The reading taken right after the command was sent: time 0, and the twin's start state.
    prediction_.emplace(std::move(twin_), limits_, move_, *result.reading);
    pending_reading_ = *result.reading;
    ProcessLocked();
  }

  void OnReading(const gateway::DeviceReading& reading) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!prediction_ || reading.time <= prediction_->start_time()) return;
    pending_reading_ = reading;  // newest only: the twin catches up to it in one go
    ProcessLocked();
  }

  // Steps the twin to the newest reading on the pool (one job at a time).
  void ProcessLocked() {
    if (busy_ || !pending_reading_ || !reactor_ || finished_ || done_) return;
    busy_ = true;
    const gateway::DeviceReading reading = *pending_reading_;
    pending_reading_.reset();
    pool_->Post([self = shared_from_this(), reading] {
      std::lock_guard<std::mutex> lock(self->mutex_);
      self->busy_ = false;
      if (!self->reactor_ || self->finished_) return;
      try {
        self->QueueLocked(self->prediction_->Next(reading));
      } catch (const Error& error) {
        self->FinishLocked(ToStatus(error));
        return;
      }
      self->ProcessLocked();
    });
  }

  void QueueLocked(const gateway::PredictionSample& sample) {
    if (!gate_.Due(sample)) return;
    v1::PredictionSample& out = queue_.emplace_back();
    out.set_time(sample.time);
    ToProto(sample.predicted, out.mutable_predicted());
    ToProto(sample.measured, out.mutable_measured());
    out.set_surprise(sample.surprise);
    out.set_done(sample.done);
    if (recordings_) recordings_->Append(scene_id_, "/graspsim/gateway/prediction", out);
    if (sample.done) {
      done_ = true;
      finish_pending_ = std::make_unique<grpc::Status>(grpc::Status::OK);
    }
    WriteNextLocked();
  }

  void WriteNextLocked() {
    if (writing_ || !reactor_ || finished_) return;
    if (!queue_.empty() && written_) queue_.pop_front();  // the sample whose write completed
    written_ = false;
    if (queue_.empty()) {
      if (finish_pending_) FinishLocked(*finish_pending_);
      return;
    }
    writing_ = written_ = true;
    reactor_->StartWrite(&queue_.front());
  }

  void TimedOut(double timeout) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!reactor_ || finished_ || done_) return;
      FinishLocked(grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED,
                                "device '" + device_id_ + "': the fingers did not stop within timeout " +
                                    std::to_string(timeout) + " s; a stop was sent"));
    }
    gateway::Command stop;
    stop.device_id = device_id_;
    stop.kind = gateway::Command::Kind::kStop;
    hub_->Submit(stop, [](const gateway::CommandResult&) {});
  }

  void FinishLocked(const grpc::Status& status) {
    if (!reactor_ || finished_) return;
    if (writing_) {
      if (!finish_pending_ || finish_pending_->ok()) finish_pending_ = std::make_unique<grpc::Status>(status);
      return;
    }
    finished_ = true;
    LogRequest(kMethod, *context_, status, std::chrono::steady_clock::now() - begun_);
    reactor_->Finish(status);
  }

  std::mutex mutex_;
  grpc::ServerWriteReactor<v1::PredictionSample>* reactor_;
  RecordingLog* recordings_ = nullptr;
  std::string scene_id_;
  grpc::CallbackServerContext* context_;
  gateway::GatewayHub* hub_;
  WorkerPool* pool_;
  const std::chrono::steady_clock::time_point begun_;
  std::string device_id_;
  gateway::DeviceLimits limits_;
  gateway::Move move_;
  gateway::SampleGate gate_{50};
  grpc::Alarm deadline_alarm_;
  uint64_t subscription_ = 0;
  std::unique_ptr<gateway::SimulatedGripper> twin_;  // until the action starts
  std::optional<gateway::ActionPrediction> prediction_;
  std::optional<gateway::DeviceReading> pending_reading_;
  std::deque<v1::PredictionSample> queue_;
  bool busy_ = false, writing_ = false, written_ = false, finished_ = false, done_ = false;
  std::unique_ptr<grpc::Status> finish_pending_;
};

using PredictionReactor = RunReactor<v1::PredictionSample, PredictionRun>;

}  // namespace

grpc::ServerWriteReactor<v1::PredictionSample>* StartPredictAction(grpc::CallbackServerContext* context,
                                                                   const v1::PredictActionRequest* request,
                                                                   gateway::GatewayHub* hub, SceneRegistry* registry,
                                                                   WorkerPool* pool, RecordingLog* recordings) {
  std::optional<gateway::DeviceInfo> device;
  std::shared_ptr<Scene> scene;
  gateway::Move move;
  gateway::PredictionTiming timing;
  const grpc::Status status = Handle(kMethod, *context, [&] {
    if (request->device_id().empty()) ThrowInvalidArgument("device_id: empty");
    device = hub->Find(request->device_id());
    if (!device) ThrowNotFound("device_id: no device '" + request->device_id() + "' is registered");
    scene = registry->Get(request->scene_id());
    if (!scene) ThrowNotFound("scene_id: no scene '" + request->scene_id() + "'");
    if (request->gripper_id().empty()) ThrowInvalidArgument("gripper_id: empty");
    if (!request->has_move()) ThrowInvalidArgument("move: not set (the action's target opening, speed and force)");
    move = MoveFromProto("move", request->move());
    timing = gateway::PredictionTimingFrom(request->timeout(), request->rate_hz());
  });
  if (!status.ok()) return new FailedWriter<v1::PredictionSample>(status);
  auto* reactor = new PredictionReactor(context, hub, pool);
  SceneView view = scene->View();
  if (recordings) recordings->Append(scene->id(), "/graspsim/gateway/action", *request);
  reactor->run()->Start(device->id, device->limits, move, timing, std::move(view.model),
                        std::move(view.state), request->gripper_id(), recordings, scene->id());
  return reactor;
}

}  // namespace graspsim::rpc
