// graspsim.v1.SceneService: translation between messages and the world and physics libraries; no logic of its
// own beyond the request's shape. Every method uses gRPC's callback API (a server that mixes it with the
// synchronous API stalls its synchronous calls for ~100 ms about once a second in gRPC 1.51); bodies run on
// the worker pool, WatchScene is a reactor per viewer.
#pragma once

#include "core/worker_pool.h"
#include "physics/simulation_cache.h"
#include "graspsim/v1/scene.grpc.pb.h"
#include "world/scene_registry.h"

namespace graspsim::rpc {

class SceneServiceImpl final : public v1::SceneService::CallbackService {
 public:
  // `simulations` is shared with TactileService (its work cycle steps the same scenes); it outlives the service.
  SceneServiceImpl(SceneRegistry* registry, WorkerPool* pool, SimulationCache* simulations, double watch_max_rate_hz)
      : registry_(registry), pool_(pool), simulations_(simulations), watch_max_rate_hz_(watch_max_rate_hz) {}

  using Context = grpc::CallbackServerContext;
  using Unary = grpc::ServerUnaryReactor;

  Unary* CreateScene(Context*, const v1::CreateSceneRequest*, v1::Scene*) override;
  Unary* ListScenes(Context*, const v1::ListScenesRequest*, v1::ListScenesResponse*) override;
  Unary* GetScene(Context*, const v1::GetSceneRequest*, v1::Scene*) override;
  Unary* DeleteScene(Context*, const v1::DeleteSceneRequest*, v1::DeleteSceneResponse*) override;
  grpc::ServerReadReactor<v1::UploadFileChunk>* UploadFile(Context*, v1::FileInfo*) override;
  grpc::ServerWriteReactor<v1::SceneArchiveChunk>* ExportScene(Context*, const v1::ExportSceneRequest*) override;
  grpc::ServerReadReactor<v1::SceneArchiveChunk>* ImportScene(Context*, v1::Scene*) override;
  Unary* ListBuiltinModels(Context*, const v1::ListBuiltinModelsRequest*, v1::ListBuiltinModelsResponse*) override;
  Unary* AddObject(Context*, const v1::AddObjectRequest*, v1::Body*) override;
  Unary* AddRobot(Context*, const v1::AddRobotRequest*, v1::AddRobotResponse*) override;
  Unary* RemoveBody(Context*, const v1::RemoveBodyRequest*, v1::RemoveBodyResponse*) override;
  Unary* SetBodyPoses(Context*, const v1::SetBodyPosesRequest*, v1::SetBodyPosesResponse*) override;
  Unary* GetBodyPoses(Context*, const v1::GetBodyPosesRequest*, v1::GetBodyPosesResponse*) override;
  Unary* SetJointPositions(Context*, const v1::SetJointPositionsRequest*, v1::SetJointPositionsResponse*) override;
  Unary* GetJointPositions(Context*, const v1::GetJointPositionsRequest*, v1::GetJointPositionsResponse*) override;
  grpc::ServerWriteReactor<v1::SceneSnapshot>* WatchScene(Context*, const v1::WatchSceneRequest*) override;
  // Simulation (simulation_service.cpp).
  Unary* StepSimulation(Context*, const v1::StepSimulationRequest*, v1::StepSimulationResponse*) override;
  Unary* SetSimulationParams(Context*, const v1::SetSimulationParamsRequest*, v1::SimulationParams*) override;
  Unary* GetSimulationParams(Context*, const v1::GetSimulationParamsRequest*, v1::SimulationParams*) override;
  Unary* SetActuators(Context*, const v1::SetActuatorsRequest*, v1::SetActuatorsResponse*) override;

 private:
  SceneRegistry* registry_;
  WorkerPool* pool_;
  SimulationCache* simulations_;
  const double watch_max_rate_hz_;
};

}  // namespace graspsim::rpc
