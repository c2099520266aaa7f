#include "rpc/tactile_service.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "core/error.h"
#include "core/format.h"
#include "rpc/call.h"
#include "rpc/failed_call.h"
#include "rpc/sensor_readings.h"
#include "rpc/sensor_stream.h"
#include "rpc/work_cycle_stream.h"
#include "sensors/sensor_registry.h"
#include "tactile/heat_map.h"
#include "tactile/tactile_frame.h"

namespace graspsim::rpc {
namespace {

constexpr unsigned kDefaultImageScale = 20;  // px per texel: a PG70 pad becomes 120 x 280 px
constexpr unsigned kMaxImageSide = 4096;     // px

}  // namespace

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
    const SceneView view = registry_->Get(request->scene_id())->View();
    const std::string& id = request->sensor_id();
    const SensorRef sensor = FindSensor(view, "sensor_id", id);
    if (sensor.kind != SensorRef::Kind::kTactile) {
      ThrowInvalidArgument("sensor_id: '" + id + "' is not a tactile array; images are of tactile arrays only");
    }
    const TactileArraySpec& pad = view.model->tactile_arrays[sensor.index];
    const unsigned scale = request->scale() == 0 ? kDefaultImageScale : request->scale();
    const unsigned longest = std::max(pad.rows, pad.cols);
    if (uint64_t{scale} * longest > kMaxImageSide) {
      ThrowInvalidArgument("scale: " + std::to_string(scale) + " px per texel makes the " + std::to_string(pad.cols) +
                           " x " + std::to_string(pad.rows) + " texels of '" + id + "' an image of " +
                           std::to_string(uint64_t{scale} * pad.cols) + " x " +
                           std::to_string(uint64_t{scale} * pad.rows) + " px; at most " +
                           std::to_string(kMaxImageSide) + " px per side, i.e. scale <= " +
                           std::to_string(kMaxImageSide / longest));
    }
    const TactileFrame frame = ReadTactileArray(*view.model, view.state, sensor.index);
    response->set_png(TactileImagePng(frame, pad.max_intensity, scale));
    response->set_width(pad.cols * scale);
    response->set_height(pad.rows * scale);
  });
}

grpc::ServerWriteReactor<v1::SensorReading>* TactileServiceImpl::Stream(Context* context,
                                                                        const v1::StreamRequest* request) {
  std::shared_ptr<Scene> scene;
  std::vector<std::string> ids;
  // The request's shape is checked here; the ids against the scene's model on the pool (reading the model takes
  // the scene's readers' lock, which a committing writer holds), before the first reading is written.
  auto check = [&] {
    const double rate = request->rate_hz();
    if (!std::isfinite(rate) || rate <= 0) {
      ThrowInvalidArgument("rate_hz: " + FormatNumber(rate) + " Hz; give a finite rate > 0");
    }
    if (rate > max_rate_hz_) {
      ThrowInvalidArgument("rate_hz: " + FormatNumber(rate) + " Hz is above the server's limit of " +
                           FormatNumber(max_rate_hz_) + " Hz (--watch-max-rate-hz)");
    }
    if (request->sensor_ids().empty()) ThrowInvalidArgument("sensor_ids: empty; name at least one sensor");
    std::set<std::string> seen;
    for (int i = 0; i < request->sensor_ids_size(); ++i) {
      const std::string& id = request->sensor_ids(i);
      if (!seen.insert(id).second) {
        ThrowInvalidArgument("sensor_ids[" + std::to_string(i) + "]: '" + id.substr(0, 80) + "' is listed twice");
      }
      ids.push_back(id);
    }
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
