// The services of API v1 whose capabilities later issues build. Each method answers UNIMPLEMENTED with a
// message saying which issue brings it, never a fake result. Replace a class here when its issue lands.
#pragma once

#include "graspsim/v1/gateway.grpc.pb.h"
#include "graspsim/v1/grasp.grpc.pb.h"
#include "graspsim/v1/perception.grpc.pb.h"

namespace graspsim::rpc {

using Context = grpc::CallbackServerContext;
using Unary = grpc::ServerUnaryReactor;
template <typename Response>
using Writer = grpc::ServerWriteReactor<Response>;

class PerceptionServiceStub final : public v1::PerceptionService::CallbackService {
 public:
  Writer<v1::CompleteShapeProgress>* CompleteShape(Context*, const v1::CompleteShapeRequest*) override;
  Unary* SegmentScene(Context*, const v1::SegmentSceneRequest*, v1::SegmentSceneResponse*) override;
};

class GraspServiceStub final : public v1::GraspService::CallbackService {
 public:
  Writer<v1::PlanGraspsProgress>* PlanGrasps(Context*, const v1::PlanGraspsRequest*) override;
  Unary* SimulateGrasp(Context*, const v1::SimulateGraspRequest*, v1::Grasp*) override;
  Unary* PlanArmPath(Context*, const v1::PlanArmPathRequest*, v1::PlanArmPathResponse*) override;
  Writer<v1::PickAndPlaceProgress>* PickAndPlace(Context*, const v1::PickAndPlaceRequest*) override;
};

class GatewayServiceStub final : public v1::GatewayService::CallbackService {
 public:
  grpc::ServerBidiReactor<v1::GatewayMessage, v1::GatewayCommand>* Connect(Context*) override;
  Unary* ListDevices(Context*, const v1::ListDevicesRequest*, v1::ListDevicesResponse*) override;
  Unary* SendCommand(Context*, const v1::DeviceCommand*, v1::CommandResult*) override;
};

}  // namespace graspsim::rpc
