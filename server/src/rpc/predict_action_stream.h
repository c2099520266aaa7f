// GatewayService.PredictAction: one real gripper action with its simulated twin beside it, as a write reactor
// per run (rpc/run_reactor.h). The run relays the move to the device's gateway, follows the device's readings
// as they arrive, steps the simulated PG70 (gateway/action_prediction.h) to each reading's time on the worker
// pool and streams predicted and measured readings with their surprise, until the real fingers stop. When the
// twin's scene is being recorded, the action and every sample go into its recording too (recording_log.h).
#pragma once

#include <grpcpp/grpcpp.h>

#include "core/worker_pool.h"
#include "gateway/gateway_hub.h"
#include "graspsim/v1/gateway.grpc.pb.h"
#include "rpc/recording_log.h"
#include "world/scene_registry.h"

namespace graspsim::rpc {

grpc::ServerWriteReactor<v1::PredictionSample>* StartPredictAction(grpc::CallbackServerContext* context,
                                                                   const v1::PredictActionRequest* request,
                                                                   gateway::GatewayHub* hub, SceneRegistry* registry,
                                                                   WorkerPool* pool, RecordingLog* recordings);

}  // namespace graspsim::rpc
