// The one table of who may call what. Every method of every service the server registers has a row; a new RPC
// without one is refused at run time and fails tests/cpp/auth/role_table_test.cpp, which walks the descriptors.
#include "auth/auth.h"

namespace graspsim::auth {

const std::map<std::string, MethodRule, std::less<>>& RoleTable() {
  using enum Role;
  using A = SceneAccess;
  static const std::map<std::string, MethodRule, std::less<>> table = {
      // SceneService: reading and watching is viewer's; everything that changes a scene is scripter's.
      {"/graspsim.v1.SceneService/CreateScene", {kScripter, A::kNone}},
      {"/graspsim.v1.SceneService/ListScenes", {kViewer, A::kNone}},  // the answer lists only readable scenes
      {"/graspsim.v1.SceneService/GetScene", {kViewer, A::kRead}},
      {"/graspsim.v1.SceneService/DeleteScene", {kScripter, A::kWrite}},
      {"/graspsim.v1.SceneService/ExportScene", {kViewer, A::kRead}},  // what GetScene with geometry shows
      {"/graspsim.v1.SceneService/ImportScene", {kScripter, A::kNone}},  // creates a scene, as CreateScene
      {"/graspsim.v1.SceneService/UploadFile", {kScripter, A::kWrite}},
      {"/graspsim.v1.SceneService/ListBuiltinModels", {kViewer, A::kNone}},
      {"/graspsim.v1.SceneService/AddObject", {kScripter, A::kWrite}},
      {"/graspsim.v1.SceneService/AddRobot", {kScripter, A::kWrite}},
      {"/graspsim.v1.SceneService/RemoveBody", {kScripter, A::kWrite}},
      {"/graspsim.v1.SceneService/SetBodyPoses", {kScripter, A::kWrite}},
      {"/graspsim.v1.SceneService/GetBodyPoses", {kViewer, A::kRead}},
      {"/graspsim.v1.SceneService/SetJointPositions", {kScripter, A::kWrite}},
      {"/graspsim.v1.SceneService/GetJointPositions", {kViewer, A::kRead}},
      {"/graspsim.v1.SceneService/WatchScene", {kViewer, A::kRead}},
      {"/graspsim.v1.SceneService/StepSimulation", {kScripter, A::kWrite}},
      {"/graspsim.v1.SceneService/SetSimulationParams", {kScripter, A::kWrite}},
      {"/graspsim.v1.SceneService/GetSimulationParams", {kViewer, A::kRead}},
      {"/graspsim.v1.SceneService/SetActuators", {kScripter, A::kWrite}},
      // PerceptionService: computing is scripter's; a completion may add its mesh to the named scene.
      {"/graspsim.v1.PerceptionService/CompleteShape", {kScripter, A::kWrite}},
      {"/graspsim.v1.PerceptionService/SegmentScene", {kScripter, A::kNone}},
      // GraspService: planning reads the scene; grasp sets are keyed by content hash and readable by viewers.
      {"/graspsim.v1.GraspService/PlanGrasps", {kScripter, A::kRead}},
      {"/graspsim.v1.GraspService/GetGraspSet", {kViewer, A::kNone}},
      {"/graspsim.v1.GraspService/EvaluateGrasp", {kScripter, A::kRead}},
      {"/graspsim.v1.GraspService/PlanArmPath", {kScripter, A::kRead}},
      {"/graspsim.v1.GraspService/PlanArmPaths", {kScripter, A::kRead}},
      {"/graspsim.v1.GraspService/PickAndPlace", {kScripter, A::kWrite}},
      // TactileService: sampling and streaming a scene's sensors is watching; a work cycle moves the scene.
      {"/graspsim.v1.TactileService/Sample", {kViewer, A::kRead}},
      {"/graspsim.v1.TactileService/Stream", {kViewer, A::kRead}},
      {"/graspsim.v1.TactileService/GetTactileImage", {kViewer, A::kRead}},
      {"/graspsim.v1.TactileService/RunWorkCycle", {kScripter, A::kWrite}},
      // GatewayService: only gateways connect; commands move real hardware and need a grant for the device.
      // An emergency stop only ever stops motion, so every scripter may send it.
      {"/graspsim.v1.GatewayService/Connect", {kGateway, A::kNone}},
      {"/graspsim.v1.GatewayService/ListDevices", {kViewer, A::kNone}},
      {"/graspsim.v1.GatewayService/SendCommand", {kScripter, A::kNone, true}},
      {"/graspsim.v1.GatewayService/EmergencyStop", {kScripter, A::kNone}},
      {"/graspsim.v1.GatewayService/PredictAction", {kScripter, A::kWrite, true}},
      // AuthService: tokens and grants are admin's; a scene's owner shares it (kWrite = owner or admin).
      {"/graspsim.v1.AuthService/WhoAmI", {kViewer, A::kNone}},
      {"/graspsim.v1.AuthService/AddToken", {kAdmin, A::kNone}},
      {"/graspsim.v1.AuthService/RevokeToken", {kAdmin, A::kNone}},
      {"/graspsim.v1.AuthService/GrantDevice", {kAdmin, A::kNone}},
      {"/graspsim.v1.AuthService/ShareScene", {kScripter, A::kWrite}},
      // Health checks answer load balancers and probes without a token; reflection describes the API.
      // RecordingService: starting and stopping a scene's recording writes to it; the files are the server's, read by
      // any viewer; a replay makes a new scene (scripter's, owned by its caller).
      {"/graspsim.v1.RecordingService/StartRecording", {kScripter, A::kWrite}},
      {"/graspsim.v1.RecordingService/StopRecording", {kScripter, A::kWrite}},
      {"/graspsim.v1.RecordingService/ListRecordings", {kViewer, A::kNone}},
      {"/graspsim.v1.RecordingService/DownloadRecording", {kViewer, A::kNone}},
      {"/graspsim.v1.RecordingService/ReplayRecording", {kScripter, A::kNone}},
      {"/graspsim.v1.RecordingService/SeekReplay", {kScripter, A::kWrite}},

      {"/grpc.health.v1.Health/Check", {kPublic, A::kNone}},
      {"/grpc.health.v1.Health/Watch", {kPublic, A::kNone}},
      {"/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo", {kViewer, A::kNone}},
  };
  return table;
}

}  // namespace graspsim::auth
