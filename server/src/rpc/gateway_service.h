// graspsim.v1.GatewayService: translation between the gateway messages and the hub (gateway/gateway_hub.h).
// Connect is a bidi reactor per gateway (gateway_stream.h); SendCommand and EmergencyStop finish from the
// hub's completion callbacks (nothing blocks while a gateway works); PredictAction is a write reactor per run
// (predict_action_stream.h).
#pragma once

#include "core/worker_pool.h"
#include "gateway/gateway_hub.h"
#include "graspsim/v1/gateway.grpc.pb.h"
#include "rpc/recording_log.h"
#include "world/scene_registry.h"

namespace graspsim::rpc {

class GatewayServiceImpl final : public v1::GatewayService::CallbackService {
 public:
  // `recordings` (may be null) takes PredictAction's samples into the twin scene's recording.
  GatewayServiceImpl(gateway::GatewayHub* hub, SceneRegistry* registry, WorkerPool* pool, RecordingLog* recordings)
      : hub_(hub), registry_(registry), pool_(pool), recordings_(recordings) {}

  using Context = grpc::CallbackServerContext;
  using Unary = grpc::ServerUnaryReactor;

  grpc::ServerBidiReactor<v1::GatewayMessage, v1::GatewayCommand>* Connect(Context*) override;
  Unary* ListDevices(Context*, const v1::ListDevicesRequest*, v1::ListDevicesResponse*) override;
  Unary* SendCommand(Context*, const v1::DeviceCommand*, v1::CommandResult*) override;
  Unary* EmergencyStop(Context*, const v1::EmergencyStopRequest*, v1::EmergencyStopResponse*) override;
  grpc::ServerWriteReactor<v1::PredictionSample>* PredictAction(Context*, const v1::PredictActionRequest*) override;

 private:
  gateway::GatewayHub* hub_;
  SceneRegistry* registry_;
  WorkerPool* pool_;
  RecordingLog* recordings_;
};

}  // namespace graspsim::rpc
