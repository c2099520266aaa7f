#include "rpc/gateway_service.h"

#include "rpc/call.h"
#include "rpc/convert_gateway.h"
#include "rpc/failed_call.h"
#include "rpc/gateway_stream.h"
#include "rpc/predict_action_stream.h"

namespace graspsim::rpc {
namespace {

grpc::Status StatusOf(const gateway::CommandResult& result) {
  if (result.ok()) return grpc::Status::OK;
  return grpc::Status(static_cast<grpc::StatusCode>(result.code), result.message);
}

}  // namespace

grpc::ServerBidiReactor<v1::GatewayMessage, v1::GatewayCommand>* GatewayServiceImpl::Connect(Context* context) {
  // Refused before the stream opens a hub session: a caller who sends nothing must not hold one (it did,
  // tests/python/test_auth_every_method.py).
  if (auto refused = RefusedCall(*context)) {
    return new FailedBidi<v1::GatewayMessage, v1::GatewayCommand>(*refused);
  }
  return StartGatewayStream(context, hub_);
}

grpc::ServerUnaryReactor* GatewayServiceImpl::ListDevices(Context* context, const v1::ListDevicesRequest*,
                                                          v1::ListDevicesResponse* response) {
  const grpc::Status status = Handle("GatewayService/ListDevices", *context, [&] {
    for (const gateway::DeviceInfo& device : hub_->Devices()) ToProto(device, response->add_devices());
  });
  return FailedUnary(context, status);  // finishes at once, with OK too
}

grpc::ServerUnaryReactor* GatewayServiceImpl::SendCommand(Context* context, const v1::DeviceCommand* request,
                                                          v1::CommandResult* response) {
  constexpr char kMethod[] = "GatewayService/SendCommand";
  gateway::Command command;
  const grpc::Status status = Handle(kMethod, *context, [&] { command = CommandFromProto(*request); });
  if (!status.ok()) return FailedUnary(context, status);
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  const auto start = std::chrono::steady_clock::now();
  hub_->Submit(command, [=](const gateway::CommandResult& result) {
    const grpc::Status outcome = StatusOf(result);
    if (outcome.ok()) ToProto(result, response);
    LogRequest(kMethod, *context, outcome, std::chrono::steady_clock::now() - start);
    reactor->Finish(outcome);
  });
  return reactor;
}

grpc::ServerUnaryReactor* GatewayServiceImpl::EmergencyStop(Context* context, const v1::EmergencyStopRequest* request,
                                                            v1::EmergencyStopResponse* response) {
  constexpr char kMethod[] = "GatewayService/EmergencyStop";
  if (auto refused = RefusedCall(*context)) return FailedUnary(context, *refused);
  if (!request->device_id().empty() && !hub_->Find(request->device_id())) {
    const grpc::Status status(grpc::StatusCode::NOT_FOUND,
                              "device_id: no device '" + request->device_id() + "' is registered");
    LogRequest(kMethod, *context, status, {});
    return FailedUnary(context, status);
  }
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  constexpr double kStopTimeout = 2;  // s: a gateway that cannot confirm a stop by then is reported as failed
  hub_->EmergencyStop(request->device_id(), kStopTimeout, [=](const auto& results) {
    for (const auto& [id, result] : results) {
      if (result.ok()) {
        response->add_stopped(id);
      } else {
        response->add_failed(id + ": " + result.message);
      }
    }
    LogRequest(kMethod, *context, grpc::Status::OK, {});
    reactor->Finish(grpc::Status::OK);
  });
  return reactor;
}

grpc::ServerWriteReactor<v1::PredictionSample>* GatewayServiceImpl::PredictAction(
    Context* context, const v1::PredictActionRequest* request) {
  return StartStream<v1::PredictionSample>(
      context, [&] { return StartPredictAction(context, request, hub_, registry_, pool_, recordings_); });
}

}  // namespace graspsim::rpc
