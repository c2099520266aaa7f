#include "rpc/unimplemented_services.h"

#include <string>

#include "rpc/call.h"
#include "rpc/failed_call.h"

namespace graspsim::rpc {
namespace {

grpc::Status NotBuiltYet(const Context& context, const char* method, const char* capability) {
  const grpc::Status status(grpc::StatusCode::UNIMPLEMENTED,
                            std::string("graspsim.v1.") + method + " is declared in API v1 but not implemented yet: " +
                                capability + " is a later issue");
  LogRequest(method, context, status, {});
  return status;
}

template <typename Response>
Writer<Response>* NotBuiltYetStream(Context* context, const char* method, const char* capability) {
  return new FailedWriter<Response>(NotBuiltYet(*context, method, capability));
}

Unary* NotBuiltYetUnary(Context* context, const char* method, const char* capability) {
  return FailedUnary(context, NotBuiltYet(*context, method, capability));
}

constexpr char kShapeCompletion[] = "shape completion";
constexpr char kGraspPlanning[] = "grasp planning";
constexpr char kMotionPlanning[] = "arm motion planning and pick-and-place";
constexpr char kGateway[] = "the hardware gateway";

}  // namespace

Writer<v1::CompleteShapeProgress>* PerceptionServiceStub::CompleteShape(Context* c, const v1::CompleteShapeRequest*) {
  return NotBuiltYetStream<v1::CompleteShapeProgress>(c, "PerceptionService/CompleteShape", kShapeCompletion);
}
Unary* PerceptionServiceStub::SegmentScene(Context* c, const v1::SegmentSceneRequest*, v1::SegmentSceneResponse*) {
  return NotBuiltYetUnary(c, "PerceptionService/SegmentScene", kShapeCompletion);
}

Writer<v1::PlanGraspsProgress>* GraspServiceStub::PlanGrasps(Context* c, const v1::PlanGraspsRequest*) {
  return NotBuiltYetStream<v1::PlanGraspsProgress>(c, "GraspService/PlanGrasps", kGraspPlanning);
}
Unary* GraspServiceStub::SimulateGrasp(Context* c, const v1::SimulateGraspRequest*, v1::Grasp*) {
  return NotBuiltYetUnary(c, "GraspService/SimulateGrasp", kGraspPlanning);
}
Unary* GraspServiceStub::PlanArmPath(Context* c, const v1::PlanArmPathRequest*, v1::PlanArmPathResponse*) {
  return NotBuiltYetUnary(c, "GraspService/PlanArmPath", kMotionPlanning);
}
Writer<v1::PickAndPlaceProgress>* GraspServiceStub::PickAndPlace(Context* c, const v1::PickAndPlaceRequest*) {
  return NotBuiltYetStream<v1::PickAndPlaceProgress>(c, "GraspService/PickAndPlace", kMotionPlanning);
}

grpc::ServerBidiReactor<v1::GatewayMessage, v1::GatewayCommand>* GatewayServiceStub::Connect(Context* c) {
  return new FailedBidi<v1::GatewayMessage, v1::GatewayCommand>(NotBuiltYet(*c, "GatewayService/Connect", kGateway));
}
Unary* GatewayServiceStub::ListDevices(Context* c, const v1::ListDevicesRequest*, v1::ListDevicesResponse*) {
  return NotBuiltYetUnary(c, "GatewayService/ListDevices", kGateway);
}
Unary* GatewayServiceStub::SendCommand(Context* c, const v1::DeviceCommand*, v1::CommandResult*) {
  return NotBuiltYetUnary(c, "GatewayService/SendCommand", kGateway);
}

}  // namespace graspsim::rpc
