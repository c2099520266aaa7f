// graspsim.v1.SceneService: translation between messages and the world library; no logic of its own beyond
// validation of the request's shape. Unary and upload calls run on the synchronous server's thread pool;
// WatchScene uses the callback API so that a viewer holds no thread.
#pragma once

#include <chrono>

#include "graspsim/v1/scene.grpc.pb.h"
#include "world/scene_registry.h"

namespace graspsim::rpc {

class SceneServiceImpl final : public v1::SceneService::WithCallbackMethod_WatchScene<v1::SceneService::Service> {
 public:
  SceneServiceImpl(SceneRegistry* registry, double watch_max_rate_hz)
      : registry_(registry), watch_max_rate_hz_(watch_max_rate_hz) {}

  grpc::Status CreateScene(grpc::ServerContext*, const v1::CreateSceneRequest*, v1::Scene*) override;
  grpc::Status ListScenes(grpc::ServerContext*, const v1::ListScenesRequest*, v1::ListScenesResponse*) override;
  grpc::Status GetScene(grpc::ServerContext*, const v1::GetSceneRequest*, v1::Scene*) override;
  grpc::Status DeleteScene(grpc::ServerContext*, const v1::DeleteSceneRequest*, v1::DeleteSceneResponse*) override;
  grpc::Status UploadFile(grpc::ServerContext*, grpc::ServerReader<v1::UploadFileChunk>*, v1::FileInfo*) override;
  grpc::Status ListBuiltinModels(grpc::ServerContext*, const v1::ListBuiltinModelsRequest*,
                                 v1::ListBuiltinModelsResponse*) override;
  grpc::Status AddObject(grpc::ServerContext*, const v1::AddObjectRequest*, v1::Body*) override;
  grpc::Status AddRobot(grpc::ServerContext*, const v1::AddRobotRequest*, v1::AddRobotResponse*) override;
  grpc::Status RemoveBody(grpc::ServerContext*, const v1::RemoveBodyRequest*, v1::RemoveBodyResponse*) override;
  grpc::Status SetBodyPoses(grpc::ServerContext*, const v1::SetBodyPosesRequest*,
                            v1::SetBodyPosesResponse*) override;
  grpc::Status GetBodyPoses(grpc::ServerContext*, const v1::GetBodyPosesRequest*,
                            v1::GetBodyPosesResponse*) override;
  grpc::Status SetJointPositions(grpc::ServerContext*, const v1::SetJointPositionsRequest*,
                                 v1::SetJointPositionsResponse*) override;
  grpc::Status GetJointPositions(grpc::ServerContext*, const v1::GetJointPositionsRequest*,
                                 v1::GetJointPositionsResponse*) override;
  grpc::ServerWriteReactor<v1::SceneSnapshot>* WatchScene(grpc::CallbackServerContext*,
                                                          const v1::WatchSceneRequest*) override;
  grpc::Status StepSimulation(grpc::ServerContext*, const v1::StepSimulationRequest*,
                              v1::StepSimulationResponse*) override;

 private:
  SceneRegistry* registry_;
  const double watch_max_rate_hz_;
};

}  // namespace graspsim::rpc
