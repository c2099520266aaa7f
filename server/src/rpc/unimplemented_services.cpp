#include "rpc/unimplemented_services.h"

#include <string>

#include "rpc/call.h"

namespace graspsim::rpc {
namespace {

grpc::Status NotBuiltYet(const grpc::ServerContext& context, const char* method, const char* capability) {
  const grpc::Status status(grpc::StatusCode::UNIMPLEMENTED,
                            std::string("graspsim.v1.") + method + " is declared in API v1 but not implemented yet: " +
                                capability + " is a later issue");
  LogRequest(method, context, status, {});
  return status;
}

constexpr char kShapeCompletion[] = "shape completion";
constexpr char kGraspPlanning[] = "grasp planning";
constexpr char kMotionPlanning[] = "arm motion planning and pick-and-place";
constexpr char kTactile[] = "tactile sensing";
constexpr char kGateway[] = "the hardware gateway";

}  // namespace

grpc::Status PerceptionServiceStub::CompleteShape(grpc::ServerContext* c, const v1::CompleteShapeRequest*,
                                                  grpc::ServerWriter<v1::CompleteShapeProgress>*) {
  return NotBuiltYet(*c, "PerceptionService/CompleteShape", kShapeCompletion);
}
grpc::Status PerceptionServiceStub::SegmentScene(grpc::ServerContext* c, const v1::SegmentSceneRequest*,
                                                 v1::SegmentSceneResponse*) {
  return NotBuiltYet(*c, "PerceptionService/SegmentScene", kShapeCompletion);
}

grpc::Status GraspServiceStub::PlanGrasps(grpc::ServerContext* c, const v1::PlanGraspsRequest*,
                                          grpc::ServerWriter<v1::PlanGraspsProgress>*) {
  return NotBuiltYet(*c, "GraspService/PlanGrasps", kGraspPlanning);
}
grpc::Status GraspServiceStub::SimulateGrasp(grpc::ServerContext* c, const v1::SimulateGraspRequest*, v1::Grasp*) {
  return NotBuiltYet(*c, "GraspService/SimulateGrasp", kGraspPlanning);
}
grpc::Status GraspServiceStub::PlanArmPath(grpc::ServerContext* c, const v1::PlanArmPathRequest*,
                                           v1::PlanArmPathResponse*) {
  return NotBuiltYet(*c, "GraspService/PlanArmPath", kMotionPlanning);
}
grpc::Status GraspServiceStub::PickAndPlace(grpc::ServerContext* c, const v1::PickAndPlaceRequest*,
                                            grpc::ServerWriter<v1::PickAndPlaceProgress>*) {
  return NotBuiltYet(*c, "GraspService/PickAndPlace", kMotionPlanning);
}

grpc::Status TactileServiceStub::Sample(grpc::ServerContext* c, const v1::SampleRequest*, v1::SensorReading*) {
  return NotBuiltYet(*c, "TactileService/Sample", kTactile);
}
grpc::Status TactileServiceStub::Stream(grpc::ServerContext* c, const v1::StreamRequest*,
                                        grpc::ServerWriter<v1::SensorReading>*) {
  return NotBuiltYet(*c, "TactileService/Stream", kTactile);
}
grpc::Status TactileServiceStub::GetTactileImage(grpc::ServerContext* c, const v1::GetTactileImageRequest*,
                                                 v1::TactileImage*) {
  return NotBuiltYet(*c, "TactileService/GetTactileImage", kTactile);
}
grpc::Status TactileServiceStub::RunWorkCycle(grpc::ServerContext* c, const v1::RunWorkCycleRequest*,
                                              grpc::ServerWriter<v1::WorkCycleProgress>*) {
  return NotBuiltYet(*c, "TactileService/RunWorkCycle", kTactile);
}

grpc::Status GatewayServiceStub::Connect(grpc::ServerContext* c,
                                         grpc::ServerReaderWriter<v1::GatewayCommand, v1::GatewayMessage>*) {
  return NotBuiltYet(*c, "GatewayService/Connect", kGateway);
}
grpc::Status GatewayServiceStub::ListDevices(grpc::ServerContext* c, const v1::ListDevicesRequest*,
                                             v1::ListDevicesResponse*) {
  return NotBuiltYet(*c, "GatewayService/ListDevices", kGateway);
}
grpc::Status GatewayServiceStub::SendCommand(grpc::ServerContext* c, const v1::DeviceCommand*, v1::CommandResult*) {
  return NotBuiltYet(*c, "GatewayService/SendCommand", kGateway);
}

}  // namespace graspsim::rpc
