#include "rpc/predict_action_stream.h"

#include "rpc/unimplemented_services.h"

namespace graspsim::rpc {

grpc::ServerWriteReactor<v1::PredictionSample>* StartPredictAction(grpc::CallbackServerContext* context,
                                                                   const v1::PredictActionRequest*,
                                                                   gateway::GatewayHub*, SceneRegistry*, WorkerPool*) {
  return NotBuiltYetStream<v1::PredictionSample>(context, "GatewayService/PredictAction", "prediction and surprise");
}

}  // namespace graspsim::rpc
