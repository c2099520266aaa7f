#include "rpc/tactile_service.h"

#include <algorithm>

#include "core/error.h"
#include "rpc/call.h"
#include "rpc/failed_call.h"
#include "rpc/sensor_readings.h"
#include "rpc/sensor_stream.h"
#include "rpc/work_cycle_stream.h"
#include "sensors/sensor_registry.h"

namespace graspsim::rpc {

grpc::ServerUnaryReactor* TactileServiceImpl::Sample(Context* context, const v1::SampleRequest* request,
                                                     v1::SensorReading* response) {
  return RunUnary(context, "TactileService/Sample", pool_, [=, this] {
    const SceneView view = registry_->Get(request->scene_id())->View();
    const SensorRef sensor = FindSensor(view, "sensor_id", request->sensor_id());
    ToProto(ReadSensor(view, sensor, request->sensor_id()), response);
  });
}

grpc::ServerUnaryReactor* TactileServiceImpl::GetTactileImage(Context* context,
                                                              const v1::GetTactileImageRequest* request,
                                                              v1::TactileImage* response) {
  return RunUnary(context, "TactileService/GetTactileImage", pool_, [=, this] {
    const TactileHeatMap image =
        TactileHeatMapOf(registry_->Get(request->scene_id())->View(), request->sensor_id(), request->scale());
    response->set_png(image.png);
    response->set_width(image.width);
    response->set_height(image.height);
  });
}

grpc::ServerWriteReactor<v1::SensorReading>* TactileServiceImpl::Stream(Context* context,
                                                                        const v1::StreamRequest* request) {
  std::shared_ptr<Scene> scene;
  std::vector<std::string> ids;
  // The request's shape is checked here; the ids against the scene's model on the pool (reading the model takes
  // the scene's readers' lock, which a committing writer holds), before the first reading is written.
  auto check = [&] {
    ids.assign(request->sensor_ids().begin(), request->sensor_ids().end());
    CheckSensorStream(request->rate_hz(), max_rate_hz_, ids);
    scene = registry_->Get(request->scene_id());
  };
  return StartStream<v1::SensorReading>("TactileService/Stream", context, check, [&] {
    // Capped so that a vanishing rate cannot overflow the interval (1e18 ns: 30 years, i.e. never again).
    const double interval_ns = std::min(1e9 / request->rate_hz(), 1e18);
    return StartSensorStream(std::move(scene), std::move(ids),
                             std::chrono::nanoseconds(static_cast<int64_t>(interval_ns)), pool_, context);
  });
}

grpc::ServerWriteReactor<v1::WorkCycleProgress>* TactileServiceImpl::RunWorkCycle(
    Context* context, const v1::RunWorkCycleRequest* request) {
  return StartStream<v1::WorkCycleProgress>(context, [&]() -> grpc::ServerWriteReactor<v1::WorkCycleProgress>* {
    // 0 means the default, as the message documents; every other value is checked by the cycle (ranges, and
    // the ids against the scene's model on the pool, since reading the model takes the scene's lock).
    auto or_default = [](double value, double fallback) { return value == 0 ? fallback : value; };
    const WorkCycleRequest defaults;
    WorkCycleRequest cycle;
    cycle.gripper_id = request->gripper_id();
    cycle.object_id = request->object_id();
    cycle.tactile_setpoint = or_default(request->tactile_setpoint(), defaults.tactile_setpoint);
    cycle.lift_height = or_default(request->lift_height(), defaults.lift_height);
    cycle.coverage = or_default(request->coverage(), defaults.coverage);
    cycle.frame_rate_hz = or_default(request->frame_rate_hz(), defaults.frame_rate_hz);
    cycle.hold_time = or_default(request->hold_time(), defaults.hold_time);
    const size_t frames_per_message = std::max<uint32_t>(request->max_frames_per_message(), 1);
    std::shared_ptr<Scene> scene;
    try {
      if (frames_per_message > kMaxFramesPerMessage) {
        throw Error(ErrorCode::kInvalidArgument, "max_frames_per_message: " +
                                                     std::to_string(request->max_frames_per_message()) +
                                                     " is above " + std::to_string(kMaxFramesPerMessage));
      }
      scene = registry_->Get(request->scene_id());
    } catch (const Error& error) {
      // Logged here only when refused: a started run logs once, when it finishes.
      const grpc::Status status = ToStatus(error);
      LogRequest("TactileService/RunWorkCycle", *context, status, {});
      return new FailedWriter<v1::WorkCycleProgress>(status);
    }
    return StartWorkCycleStream(std::move(scene), std::move(cycle), frames_per_message, simulations_, pool_, context);
  });
}

}  // namespace graspsim::rpc
