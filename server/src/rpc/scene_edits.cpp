#include "rpc/scene_edits.h"

#include "core/error.h"
#include "core/validate.h"
#include "import/robot_import.h"
#include "physics/simulation.h"
#include "rpc/convert.h"

namespace graspsim::rpc {
namespace {

// Built-in models carry no mesh files.
const std::string* NoFile(const std::string&) { return nullptr; }

FileLookup LookupIn(const std::map<std::string, StoredFile>& files) {
  return [&files](const std::string& path) -> const std::string* {
    auto it = files.find(path);
    return it == files.end() ? nullptr : it->second.bytes.get();
  };
}

const BuiltinModelInfo& FindBuiltin(const std::string& name, const std::string& kind) {
  for (const auto& info : BuiltinModels()) {
    if (info.name != name) continue;
    if (info.kind != kind) {
      ThrowInvalidArgument("builtin: '" + name + "' is a " + info.kind + " model; add it with " +
                           (info.kind == "robot" ? "AddRobot" : "AddObject"));
    }
    return info;
  }
  BuiltinModelUrdf(name);  // throws kNotFound listing the known models
  ThrowNotFound("builtin: '" + name + "' is not known");
}

template <typename Request>
SceneOp OpOf(const char* kind, const Request& request) {
  SceneOp op;
  op.kind = kind;
  request.SerializeToString(&op.payload);
  return op;
}

}  // namespace

void AddObjectFromRequest(Scene* scene, const v1::AddObjectRequest& request, const Limits& limits,
                          v1::Body* response) {
  CheckName("name", request.name());
  const Pose pose = PoseFromProto("pose", request.pose());
  const ImportOptions options = ImportOptionsFromProto("import_options", request.import_options());
  BodySpec body;
  body.id = request.name();
  body.motion = request.is_static() ? BodyMotion::kStatic : BodyMotion::kFree;
  std::vector<ImportWarning> warnings;
  switch (request.source_case()) {
    case v1::AddObjectRequest::kGeometry: {
      const auto files = scene->Files();  // meshes are parsed outside the scene's lock
      body.collision.push_back(GeometryFromProto("geometry", request.geometry(), LookupIn(files), limits));
      // A static body never moves: it needs no mass.
      if (!request.has_inertial() && !request.is_static()) {
        body.inertial = ObjectInertialFromGeometry("inertial", body.collision, options, &warnings);
      }
      break;
    }
    case v1::AddObjectRequest::kBuiltin: {
      const BuiltinModelInfo& info = FindBuiltin(request.builtin(), "object");
      RobotDescription model = LoadUrdf(BuiltinModelUrdf(info.name), NoFile, limits);
      body.collision = std::move(model.links.front().collision);
      body.inertial = model.links.front().inertial;
      if (info.is_static) body.motion = BodyMotion::kStatic;
      break;
    }
    case v1::AddObjectRequest::SOURCE_NOT_SET:
      ThrowInvalidArgument("source: give geometry or builtin");
  }
  if (request.has_inertial()) body.inertial = InertialFromProto("inertial", request.inertial());
  if (request.has_material()) body.material = MaterialFromProto("material", request.material(), body.material);
  const SceneOp op = OpOf("AddObject", request);
  const BodySpec added = scene->AddObject(std::move(body), pose, &op);
  if (!response) return;
  ToProto(added, pose, false, response);
  for (const ImportWarning& warning : warnings) ToProto(warning, response->add_warnings());
}

void AddRobotFromRequest(Scene* scene, const v1::AddRobotRequest& request, const Limits& limits,
                         v1::AddRobotResponse* response) {
  CheckName("name", request.name());
  const Pose base_pose = PoseFromProto("base_pose", request.base_pose());
  const ImportOptions options = ImportOptionsFromProto("import_options", request.import_options());
  auto files = scene->Files();
  for (int i = 0; i < request.files_size(); ++i) {
    const auto& file = request.files(i);
    CheckRelativePath("files[" + std::to_string(i) + "].path", file.path());
    files[file.path()] = {std::make_shared<const std::string>(file.data()), ""};
  }
  std::string source;
  ImportedRobot imported;
  switch (request.source_case()) {
    case v1::AddRobotRequest::kUrdf:
      source = "urdf";
      imported = ImportUrdf(request.urdf(), LookupIn(files), options, limits);
      break;
    case v1::AddRobotRequest::kMjcf:
      source = "mjcf";
      imported = ImportMjcf(request.mjcf(), LookupIn(files), options, limits);
      break;
    case v1::AddRobotRequest::kSdf:
      source = "sdf";
      imported = ImportSdf(request.sdf(), LookupIn(files), options, limits);
      break;
    case v1::AddRobotRequest::kBuiltin:
      source = "builtin:" + FindBuiltin(request.builtin(), "robot").name;
      imported.description = LoadUrdf(BuiltinModelUrdf(request.builtin()), LookupIn(files), limits);
      break;
    case v1::AddRobotRequest::SOURCE_NOT_SET:
      ThrowInvalidArgument("source: give urdf, mjcf, sdf or builtin");
  }
  const SceneOp op = OpOf("AddRobot", request);
  const AddedRobot added = scene->AddRobot(request.name(), source, imported.description, base_pose, &op);
  if (!response) return;
  // Report the placed links as the scene holds them now.
  const SceneView view = scene->View();
  ToProto(added.robot, response->mutable_robot());
  for (const auto& body : added.bodies) {
    ToProto(body, view.state.body_poses[view.model->body_index.at(body.id)], false, response->add_bodies());
  }
  for (const auto& joint : added.joints) {
    ToProto(joint, view.state.joint_positions[view.model->joint_index.at(joint.id)], response->add_joints());
  }
  for (const auto& pad : added.tactile_arrays) ToProto(pad, response->add_tactile_arrays());
  for (const ImportWarning& warning : imported.warnings) ToProto(warning, response->add_warnings());
}

std::vector<std::string> RemoveBodyFromRequest(Scene* scene, const v1::RemoveBodyRequest& request) {
  const SceneOp op = OpOf("RemoveBody", request);
  return scene->Remove(request.id(), &op);
}

void SetSimulationParamsFromRequest(Scene* scene, const v1::SetSimulationParamsRequest& request,
                                    v1::SimulationParams* response) {
  const SimulationParams params = SimulationParamsFromProto("params", request.params(), SimulationParams());
  ValidateSimulationParams(params);
  CheckEngineSupports(*scene->View().model, params.engine);  // the engine must simulate what the scene holds
  const SceneOp op = OpOf("SetSimulationParams", request);
  scene->SetSimulationParams(params, &op);
  if (response) ToProto(params, response);
}

}  // namespace graspsim::rpc
