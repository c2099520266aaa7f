// GatewayService.Connect: one gateway's session as a bidi reactor. Reads register devices, readings, results
// and heartbeats into the hub; writes are the hub's commands and heartbeats, queued and written one at a time
// (a heartbeat is queued only when none is waiting, so a slow gateway never piles them up). A registration the
// hub refuses ends the stream with that status, so the gateway sees why.
#pragma once

#include <grpcpp/grpcpp.h>

#include "gateway/gateway_hub.h"
#include "graspsim/v1/gateway.grpc.pb.h"

namespace graspsim::rpc {

grpc::ServerBidiReactor<v1::GatewayMessage, v1::GatewayCommand>* StartGatewayStream(
    grpc::CallbackServerContext* context, gateway::GatewayHub* hub);

}  // namespace graspsim::rpc
