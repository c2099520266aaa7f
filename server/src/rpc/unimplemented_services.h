// The services of API v1 whose capabilities later issues build. Each method answers UNIMPLEMENTED with a
// message saying which issue brings it, never a fake result. Replace a class here when its issue lands.
#pragma once

#include "graspsim/v1/gateway.grpc.pb.h"
#include "graspsim/v1/grasp.grpc.pb.h"
#include "graspsim/v1/perception.grpc.pb.h"
#include "graspsim/v1/tactile.grpc.pb.h"

namespace graspsim::rpc {

class PerceptionServiceStub final : public v1::PerceptionService::Service {
 public:
  grpc::Status CompleteShape(grpc::ServerContext*, const v1::CompleteShapeRequest*,
                             grpc::ServerWriter<v1::CompleteShapeProgress>*) override;
  grpc::Status SegmentScene(grpc::ServerContext*, const v1::SegmentSceneRequest*,
                            v1::SegmentSceneResponse*) override;
};

class GraspServiceStub final : public v1::GraspService::Service {
 public:
  grpc::Status PlanGrasps(grpc::ServerContext*, const v1::PlanGraspsRequest*,
                          grpc::ServerWriter<v1::PlanGraspsProgress>*) override;
  grpc::Status SimulateGrasp(grpc::ServerContext*, const v1::SimulateGraspRequest*, v1::Grasp*) override;
  grpc::Status PlanArmPath(grpc::ServerContext*, const v1::PlanArmPathRequest*, v1::PlanArmPathResponse*) override;
  grpc::Status PickAndPlace(grpc::ServerContext*, const v1::PickAndPlaceRequest*,
                            grpc::ServerWriter<v1::PickAndPlaceProgress>*) override;
};

class TactileServiceStub final : public v1::TactileService::Service {
 public:
  grpc::Status Sample(grpc::ServerContext*, const v1::SampleRequest*, v1::SensorReading*) override;
  grpc::Status Stream(grpc::ServerContext*, const v1::StreamRequest*, grpc::ServerWriter<v1::SensorReading>*) override;
  grpc::Status GetTactileImage(grpc::ServerContext*, const v1::GetTactileImageRequest*, v1::TactileImage*) override;
  grpc::Status RunWorkCycle(grpc::ServerContext*, const v1::RunWorkCycleRequest*,
                            grpc::ServerWriter<v1::WorkCycleProgress>*) override;
};

class GatewayServiceStub final : public v1::GatewayService::Service {
 public:
  grpc::Status Connect(grpc::ServerContext*, grpc::ServerReaderWriter<v1::GatewayCommand, v1::GatewayMessage>*) override;
  grpc::Status ListDevices(grpc::ServerContext*, const v1::ListDevicesRequest*, v1::ListDevicesResponse*) override;
  grpc::Status SendCommand(grpc::ServerContext*, const v1::DeviceCommand*, v1::CommandResult*) override;
};

}  // namespace graspsim::rpc
